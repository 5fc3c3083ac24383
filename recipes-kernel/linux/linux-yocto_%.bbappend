# SPDX-License-Identifier: Apache-2.0
# RaMstix on the standard linux-yocto kernel: the release's generic standard/base branch,
# omap2plus_defconfig, and the BSP/ccomm fragments of recipes-kernel/linux/files.
FILESEXTRAPATHS:prepend:ramstix := "${THISDIR}/files:"
require ramstix-kernel.inc
