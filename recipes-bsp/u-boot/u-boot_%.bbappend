# SPDX-License-Identifier: Apache-2.0
# RaMstix (Gumstix Overo): U-Boot has had no Overo board since 2020, so the layer adds its own
# (omap3_overo_ramstix_defconfig, UBOOT_MACHINE of conf/machine/ramstix.conf) with the patch
# the Debian card's build uses, meta-ccomm/bsp/u-boot-overo/ (written for 2023.01; applies
# to upstream v2024.01, scarthgap's version, with line offsets only and builds there with
# KCFLAGS=-Werror). boot.scr from the same boot.cmd, made by u-boot's UBOOT_ENV step and
# deployed for IMAGE_BOOT_FILES.
FILESEXTRAPATHS:prepend:ramstix := "${THISDIR}/../../meta-ccomm/bsp/u-boot-overo:"
SRC_URI:append:ramstix = " file://0001-omap3-ccomm-ramstix-board.patch file://boot.cmd"
UBOOT_ENV:ramstix = "boot"
UBOOT_ENV_SUFFIX:ramstix = "scr"
