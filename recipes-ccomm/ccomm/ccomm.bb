# SPDX-License-Identifier: Apache-2.0
SUMMARY = "ccomm signal daemon, library and CLI for distributed robot control"
DESCRIPTION = "ccommd shares named signals between processes through lock-free \
               structures in POSIX shared memory and forwards them between boards \
               over raw Ethernet (EtherType 0x88B5) or UDP. libccomm is the C/C++ \
               API, ccomm the command-line client."
# nooelint: oelint.vars.homepageping - the linter runs offline
HOMEPAGE = "https://github.com/ccomm/ccomm"
BUGTRACKER = "https://github.com/ccomm/ccomm/issues"
SECTION = "net"
LICENSE = "Apache-2.0"
# the project's own SPDX declaration, from the same checkout
LIC_FILES_CHKSUM = "file://CMakeLists.txt;beginline=1;endline=1;md5=653b254f286b881bdce1d14afdede628"

DEPENDS = "rapidxml"

# The version comes from project(ccomm VERSION x.y.z) in the top-level CMakeLists.txt
# of the same checkout, so the recipe never needs a rename on a release.
def ccomm_version(d):
    import os
    import re
    path = os.path.join(d.getVar('CCOMM_LAYERDIR'), 'CMakeLists.txt')
    # re-parse the recipe when the file changes
    bb.parse.mark_dependency(d, path)
    with open(path, encoding='utf-8') as f:
        m = re.search(r'project\(\s*ccomm\s+VERSION\s+([0-9][0-9.]*)', f.read())
    if not m:
        bb.fatal('cannot read the ccomm version from %s' % path)
    return m.group(1)
# only the version string matters, not where the checkout lives
ccomm_version[vardepsexclude] = "CCOMM_LAYERDIR"
PV = "${@ccomm_version(d)}"

# No network fetch of the project: the layer is the repository root, and FILESPATH is
# extended to it, so these file:// entries are this checkout's own CMake project. Their
# content checksums (not their path) go into the task signatures, so an edit rebuilds.
# examples/ and docs/protocol.md are test data of config_test and wire_test.
# nooelint: oelint.vars.fileextrapaths,oelint.vars.outofcontext - the sources live at the layer root
FILESEXTRAPATHS:prepend := "${CCOMM_LAYERDIR}:"
SRC_URI = "file://CMakeLists.txt;subdir=${BP} \
           file://cmake;subdir=${BP} \
           file://src;subdir=${BP} \
           file://dist;subdir=${BP} \
           file://integrations;subdir=${BP} \
           ${@bb.utils.contains('PACKAGECONFIG', 'ptest', 'file://examples;subdir=${BP} file://docs/protocol.md;subdir=${BP}', '', d)} \
           file://run-ptest \
           "

# python3native: integrations/ generates the 20-sim example code with Python at build time
inherit cmake systemd pkgconfig ptest useradd python3native

PACKAGECONFIG ??= "sodium ${@bb.utils.filter('DISTRO_FEATURES', 'ptest systemd', d)}"
# the unit tests (GoogleTest) are built only to ship them in ${PN}-ptest
PACKAGECONFIG[ptest] = "-DCCOMM_BUILD_TESTS=ON,-DCCOMM_BUILD_TESTS=OFF,googletest"
PACKAGECONFIG[systemd] = "-DCCOMM_WITH_SYSTEMD=ON,-DCCOMM_WITH_SYSTEMD=OFF,systemd"
PACKAGECONFIG[sodium] = "-DCCOMM_WITH_SODIUM=ON,-DCCOMM_WITH_SODIUM=OFF,libsodium"
# Cobalt (dual kernel) build: needs the linux-ccomm-xenomai kernel on the target too
PACKAGECONFIG[xenomai] = "-DCCOMM_WITH_XENOMAI=ON -DXENO_CONFIG=${STAGING_BINDIR_CROSS}/xeno-config,-DCCOMM_WITH_XENOMAI=OFF,xenomai"

# The CMake install puts the one unit file (dist/ccommd.service, ExecStart configured to
# ${bindir}) and the default dist/signals.xml where the image wants them; the recipe
# carries no copies. -Werror stays in the project's own CI: a newer cross compiler must
# not break a distro build over a new warning.
EXTRA_OECMAKE = "-DCCOMM_SYSTEMD_UNITDIR=${systemd_system_unitdir} \
                 -DCCOMM_CONFDIR=${sysconfdir}/ccomm \
                 -DCCOMM_SYSUSERSDIR=${nonarch_libdir}/sysusers.d \
                 -DCCOMM_BUILD_BENCH=OFF \
                 -DCCOMM_SANITIZE= \
                 -DCCOMM_WERROR=OFF \
                 "

do_install_ptest() {
    install -d ${D}${PTEST_PATH}/tests
    found=0
    for t in ${B}/bin/*_test; do
        [ -x "$t" ] || continue
        install -m 0755 "$t" ${D}${PTEST_PATH}/tests/
        found=1
    done
    # a ptest package without tests would report success on the board: fail here instead
    [ "$found" = 1 ] || bbfatal "no *_test executables in ${B}/bin"
    # data the tests read from the source tree; run-ptest points CCOMM_SOURCE_DIR here
    install -d ${D}${PTEST_PATH}/source/dist ${D}${PTEST_PATH}/source/docs ${D}${PTEST_PATH}/source/examples
    install -m 0644 ${S}/dist/signals.xml ${D}${PTEST_PATH}/source/dist/
    install -m 0644 ${S}/docs/protocol.md ${D}${PTEST_PATH}/source/docs/
    install -m 0644 ${S}/examples/*.xml ${D}${PTEST_PATH}/source/examples/
}

PACKAGE_BEFORE_PN = "lib${BPN} ${PN}-cli ${PN}-fmu ${PN}-integrations"

# ccomm-board-net: the board's hostname and address from signals.xml (ccommd(8)); a
# Yocto image is a board's, so it is enabled here (the Debian package leaves it off).
SYSTEMD_SERVICE:${PN} = "ccommd.service ccomm-board-net.service"
SYSTEMD_AUTO_ENABLE:${PN} = "enable"

# ccommd.service runs as User=ccomm; dist/ccomm.sysusers.conf describes the same account
# for systemd-sysusers, created here at build time so a read-only rootfs has it too
USERADD_PACKAGES = "${PN}"
USERADD_PARAM:${PN} = "--system --user-group --home-dir / --no-create-home --shell ${base_sbindir}/nologin ccomm"

FILES:lib${BPN} += "${libdir}/libccomm${SOLIBS}"
FILES:${PN}-cli += "${bindir}/ccomm ${bindir}/ccomm-latency"
# ccomm-fmu: FMUs as real-time tasks
FILES:${PN}-fmu += "${bindir}/ccomm-fmu"
# 20-sim / Simulink templates and generators (Python scripts)
FILES:${PN}-integrations += "${datadir}/ccomm/integrations"
FILES:${PN} += "${systemd_system_unitdir}/ccommd.service ${systemd_system_unitdir}/ccomm-board-net.service \
                ${nonarch_libdir}/sysusers.d/ccomm.conf"

CONFFILES:${PN} = "${sysconfdir}/ccomm/signals.xml"

RDEPENDS:${PN}-integrations = "python3-core"
# the CLI is how a person (and the oeqa test) reads and writes signals on the board
RRECOMMENDS:${PN} = "${PN}-cli"
# a .fmu is a zip archive (unzip to run one, zip to build one)
RRECOMMENDS:${PN}-fmu = "unzip zip"

CVE_PRODUCT = "ccomm"
