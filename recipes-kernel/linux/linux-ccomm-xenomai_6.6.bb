# SPDX-License-Identifier: Apache-2.0
SUMMARY = "Linux 6.6 with Dovetail and the Xenomai 3 Cobalt core, for ccomm on RaMstix"
DESCRIPTION = "The Dovetail interrupt pipeline tree (linux-dovetail, 6.6 series) \
               with the Cobalt real-time core of Xenomai 3.3.1 merged in by \
               prepare-kernel.sh, configured through linux-yocto's kernel metadata \
               with the RaMstix BSP and ccomm fragments. Select it with \
               PREFERRED_PROVIDER_virtual/kernel = linux-ccomm-xenomai and add the \
               xenomai user-space recipe (same Xenomai release) to the image."
# nooelint: oelint.vars.homepageping - the linter runs offline
HOMEPAGE = "https://xenomai.org/"
BUGTRACKER = "https://gitlab.com/Xenomai/xenomai3/xenomai/-/issues"
SECTION = "kernel"
LICENSE = "GPL-2.0-only"
LIC_FILES_CHKSUM = "file://COPYING;md5=6bc538ed5bd9a7fc9398086aedcd7e46"

require recipes-kernel/linux/linux-yocto.inc
require ramstix-kernel.inc

# Only one kernel may provide virtual/kernel: stay out of world builds and out of the
# way of linux-yocto unless this kernel was chosen (linux-yocto-dev does the same).
# nooelint: oelint.task.noanonpython - the only way to skip a kernel that was not selected
python () {
    if d.getVar("PREFERRED_PROVIDER_virtual/kernel") != d.getVar("PN"):
        raise bb.parse.SkipRecipe("Set PREFERRED_PROVIDER_virtual/kernel to %s to enable it" % d.getVar("PN"))
}

# Xenomai 3.3.x's CI builds Cobalt against the 6.1 and the latest 6.x Dovetail branches
# on arm (multi_v7_defconfig); 6.6 is also scarthgap's linux-yocto series. The -rebase
# branch is rewritten for every stable update, so the pinned commit is fetched with
# nobranch=1 rather than checked against the moving branch head.
LINUX_VERSION = "6.6.69"
PV = "${LINUX_VERSION}+git"
KBRANCH = "v6.6.y-dovetail-rebase"
SRCREV_machine = "2899dc64fca2535f2cc699e29538b381a21adbc0"
# yocto-kernel-cache at the commit scarthgap's linux-yocto 6.6 uses
SRCREV_meta = "50530c858c90f124629dadce78f696b590747ea5"
# Xenomai tag v3.3.1; must be the same release as the xenomai user-space recipe
SRCREV_xenomai = "2f15f8c5970b23428a00ccd17249de26a240dc33"
SRCREV_FORMAT = "machine_meta_xenomai"

SRC_URI = "git://gitlab.com/Xenomai/linux-dovetail.git;protocol=https;name=machine;branch=${KBRANCH};nobranch=1 \
           git://git.yoctoproject.org/yocto-kernel-cache;type=kmeta;name=meta;branch=yocto-6.6;destsuffix=${KMETA};protocol=https \
           git://gitlab.com/Xenomai/xenomai3/xenomai.git;protocol=https;name=xenomai;branch=stable/v3.3.x;destsuffix=xenomai \
           "
KMETA = "kernel-meta"

COMPATIBLE_MACHINE = "^$"
CVE_PRODUCT = "linux_kernel"
KERNEL_FEATURES:append:ramstix = " features/ccomm/ccomm-xenomai.scc"

# prepare-kernel.sh writes the Cobalt core as a plain patch (--outpatch) instead of
# symlinking into the Xenomai checkout, so the tree in work-shared stays self-contained.
do_xenomai_prepare_kernel() {
    ${UNPACKDIR}/xenomai/scripts/prepare-kernel.sh --linux=${S} --arch=${ARCH} \
        --outpatch=${WORKDIR}/xenomai-cobalt.patch
    patch -d ${S} -p1 --forward < ${WORKDIR}/xenomai-cobalt.patch
}
do_xenomai_prepare_kernel[doc] = "Merge the Xenomai Cobalt core into the Dovetail kernel tree"
do_xenomai_prepare_kernel[dirs] = "${S}"
addtask xenomai_prepare_kernel after do_patch before do_kernel_configme
