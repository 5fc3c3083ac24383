# SPDX-License-Identifier: Apache-2.0
SUMMARY = "Xenomai 3 user-space libraries and tools for the Cobalt real-time core"
DESCRIPTION = "libcobalt (the POSIX skin ccomm's CCOMM_WITH_XENOMAI build links \
               against), the RTDM/Alchemy libraries, xeno-config and the latency \
               and test utilities. It must match the Cobalt core in \
               linux-ccomm-xenomai (same Xenomai release)."
# nooelint: oelint.vars.homepageping - the linter runs offline
HOMEPAGE = "https://xenomai.org/"
BUGTRACKER = "https://gitlab.com/Xenomai/xenomai3/xenomai/-/issues"
SECTION = "libs"
# headers: GPL with a user-space exception (include/COPYING); libraries: LGPL-2.1;
# bundled iniparser: MIT; tools and test suite: GPL-2.0
LICENSE = "LGPL-2.1-or-later & GPL-2.0-or-later & MIT"
LIC_FILES_CHKSUM = "file://include/COPYING;md5=79ed705ccb9481bf9e7026b99f4e2b0e \
                    file://lib/cobalt/COPYING;md5=68ad62c64cc6c620126241fd429e68fe \
                    file://lib/boilerplate/iniparser/LICENSE;md5=124f16654dec67923ad76a803e102463 \
                    file://kernel/cobalt/COPYING;md5=073dc31ccb2ebed70db54f1e8aeb4c33"

# Pinned by commit (tag v3.3.1) rather than by a GitLab archive tarball: generated
# archives are not byte-stable, a git commit id is a content hash of the whole tree.
SRC_URI = "git://gitlab.com/Xenomai/xenomai3/xenomai.git;protocol=https;branch=stable/v3.3.x;destsuffix=${BP}"
SRCREV = "2f15f8c5970b23428a00ccd17249de26a240dc33"

inherit autotools pkgconfig binconfig

# Cobalt core (dual kernel), matching linux-ccomm-xenomai; pshared lets several
# processes share Alchemy/POSIX objects, as libccomm does with its segment
EXTRA_OECONF = "--with-core=cobalt --enable-smp --enable-pshared \
                --with-testdir=${bindir}/xenomai-tests --with-demodir=${datadir}/xenomai/demo"
# keep Xenomai's headers (cobalt/, rtdm/, boilerplate/...) out of the system include dir
includedir = "${prefix}/include/xenomai"

COMPATIBLE_HOST = "(arm|aarch64|x86_64|i.86).*-linux.*"

PACKAGE_BEFORE_PN = "${PN}-tests ${PN}-demos"
FILES:${PN}-tests += "${bindir}/xenomai-tests"
FILES:${PN}-demos += "${datadir}/xenomai/demo"
FILES:${PN}-dev += "${libdir}/cobalt.wrappers ${libdir}/modechk.wrappers ${libdir}/dynlist.ld ${bindir}/wrap-link.sh"

CVE_PRODUCT = "xenomai"
