# SPDX-License-Identifier: Apache-2.0
# U-Boot SPL (MLO) and U-Boot (u-boot.img) for the RaMstix (Gumstix Overo), cross-built from
# Debian bookworm's u-boot source package (2023.01) with the project's own board support:
# U-Boot dropped the Overo in 2020, so meta-ccomm/bsp/u-boot-overo/ carries a patch adding
# omap3_overo_ramstix_defconfig (docs/yocto.md, "The boot loader"). The same patch and
# boot.cmd are what meta-ccomm/bsp/u-boot-overo/build (the mmdebstrap card) and the Yocto
# bbappend use: one copy, found here through FILESEXTRAPATHS.
# Package u-boot-ramstix: /usr/lib/u-boot/ramstix/{MLO,u-boot.img,boot.scr}, for the SD
# card's FAT partition; boot.scr is boot.cmd made a U-Boot script by the mkimage this
# build makes.
DESCRIPTION = "U-Boot for the RaMstix (Gumstix Overo)"
MAINTAINER = "the ccomm developers <ccomm-dev@lists.example.org>"
LICENSE = "GPL-2.0-or-later"
LIC_FILES_CHKSUM = "file://${LAYERDIR_core}/licenses/COPYING.GPLv2;md5=751419260aa954499f7abaabaa882bbe"

inherit dpkg

FILESEXTRAPATHS:prepend := "${CCOMM_TOPDIR}/meta-ccomm/bsp/u-boot-overo:"
SRC_URI = "apt://u-boot file://0001-omap3-ccomm-ramstix-board.patch file://boot.cmd"
PV = "2023.01"
S = "${WORKDIR}/u-boot-src"
U_BOOT_CONFIG = "omap3_overo_ramstix_defconfig"
COMPATIBLE_MACHINE = "^(ramstix)$"

do_prepare_build[vardeps] += "U_BOOT_CONFIG"
do_prepare_build() {
    # Debian's own packaging builds every board; this one builds the Overo's two files.
    rm -rf ${S}/debian
    mkdir -p ${S}/debian
    cat >${S}/debian/control <<'EOT'
Source: u-boot-ramstix
Section: admin
Priority: optional
Maintainer: ${MAINTAINER}
Build-Depends: debhelper-compat (= 13), bc, bison, flex, device-tree-compiler,
 libssl-dev:native, libgnutls28-dev:native, uuid-dev:native, python3:native
Standards-Version: 4.6.2
Rules-Requires-Root: no

Package: u-boot-ramstix
Architecture: ${DISTRO_ARCH}
Description: U-Boot SPL (MLO) and U-Boot for the RaMstix (Gumstix Overo)
EOT
    cat >${S}/debian/rules <<'EOT'
#!/usr/bin/make -f
ifneq ($(DEB_BUILD_GNU_TYPE),$(DEB_HOST_GNU_TYPE))
export CROSS_COMPILE=$(DEB_HOST_GNU_TYPE)-
endif
%:
	dh $@
override_dh_auto_configure:
	$(MAKE) ${U_BOOT_CONFIG}
override_dh_auto_build:
	$(MAKE) $(PARALLEL_MAKE) KCFLAGS=-Werror
	tools/mkimage -A arm -O linux -T script -C none -n "RaMstix boot" -d debian/boot.cmd boot.scr
override_dh_auto_test:
override_dh_auto_install:
	install -D -m 644 MLO debian/u-boot-ramstix/usr/lib/u-boot/ramstix/MLO
	install -D -m 644 u-boot.img debian/u-boot-ramstix/usr/lib/u-boot/ramstix/u-boot.img
	install -D -m 644 boot.scr debian/u-boot-ramstix/usr/lib/u-boot/ramstix/boot.scr
override_dh_strip:
override_dh_dwz:
EOT
    chmod +x ${S}/debian/rules
    cp ${WORKDIR}/boot.cmd ${S}/debian/boot.cmd
    mkdir -p ${S}/debian/source
    echo "1.0" >${S}/debian/source/format
    deb_add_changelog
}
