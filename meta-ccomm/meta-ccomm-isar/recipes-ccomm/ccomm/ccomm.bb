# SPDX-License-Identifier: Apache-2.0
# ccommd, libccomm0 and libccomm-dev as Debian packages, built by sbuild from this
# repository's working tree with its own Debian packaging (packaging/debian), cross-compiled
# (ISAR_CROSS_COMPILE, Isar's default). One more package, ccomm-bench, for test images: the
# latency floor programs (bench/) the QEMU suite compares ccomm with. python3-ccomm is architecture-independent and not
# built in a cross build; scripts/package builds it.
DESCRIPTION = "ccomm: real-time signal exchange between robot-control boards"
MAINTAINER = "the ccomm developers <ccomm-dev@lists.example.org>"
LICENSE = "Apache-2.0"
LIC_FILES_CHKSUM = "file://${CCOMM_TOPDIR}/LICENSE;md5=3b83ef96387f14655fc854ddc3c6bd57"

inherit dpkg

# The binary packages it builds, for IMAGE_INSTALL.
PROVIDES += "ccommd libccomm0 libccomm-dev ccomm-bench"

PV = "${@ccomm_version(d)}"
S = "${WORKDIR}/ccomm"

# The version packaging/debian/changelog states: sbuild names the packages after it.
def ccomm_version(d):
    import re
    with open(d.getVar('CCOMM_TOPDIR') + '/packaging/debian/changelog') as f:
        return re.match(r'\S+ \(([^)]+)\)', f.readline()).group(1)

# The tree is not fetched: it is the checkout this layer is in, less what the package build
# does not read (the layers, the test suites; CMake builds tests only with
# CCOMM_BUILD_TESTS, which packaging/debian turns off). What identifies its content comes
# from scripts/build-image as CCOMM_SOURCE_ID (a hash of the same files, with this list),
# so a changed tree rebuilds the packages and an unchanged one reuses them.
CCOMM_PACKAGE_EXCLUDES = "meta-ccomm recipes-ccomm recipes-kernel qemu-tests tests"
CCOMM_SOURCE_ID ??= "unknown"
do_prepare_build[vardeps] += "CCOMM_SOURCE_ID CCOMM_PACKAGE_EXCLUDES"
do_prepare_build[dirs] = "${WORKDIR}"
do_prepare_build() {
    rm -rf ${S}
    mkdir -p ${S}
    excludes=""
    for e in ${CCOMM_PACKAGE_EXCLUDES}; do excludes="$excludes --exclude=./$e"; done
    (cd ${CCOMM_TOPDIR} && tar -cf - --exclude=./.git $excludes .) | tar -xf - -C ${S}
    rm -rf ${S}/debian
    cp -r ${S}/packaging/debian ${S}/debian
    # Cross build: python3 runs during the build, so it is the build machine's (apt and
    # dpkg's :native), and so is python3-wheel (architecture-independent without a
    # Multi-Arch field: apt would look for an armhf one). pandoc and python3-setuptools are
    # Multi-Arch foreign and resolve to the build machine's unqualified (dpkg refuses
    # :native on them). Everything ccomm links against is armhf.
    sed -i -e 's/^\( *\)\(python3\|python3-wheel\),/\1\2:native,/' ${S}/debian/control
    grep -q 'python3-wheel:native' ${S}/debian/control
    # ccomm-bench: the floor programs, without the peers (LCM, iceoryx).
    sed -i 's/-DCCOMM_BUILD_BENCH=OFF/-DCCOMM_BUILD_BENCH=ON -DCCOMM_BENCH_PEERS=OFF/' ${S}/debian/rules
    grep -q 'CCOMM_BUILD_BENCH=ON' ${S}/debian/rules
    cat >>${S}/debian/control <<'EOT'

Package: ccomm-bench
Architecture: any
Depends: ${shlibs:Depends}, ${misc:Depends}, libccomm0 (= ${binary:Version})
Description: real-time signal exchange between robot-control boards (latency floors)
 The programs ccomm's latency is compared with (raw sockets, shared memory hand-off),
 for test images.
EOT
    echo usr/libexec/ccomm/bench >${S}/debian/ccomm-bench.install
}
