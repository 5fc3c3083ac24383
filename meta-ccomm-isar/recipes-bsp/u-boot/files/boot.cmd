# SPDX-License-Identifier: Apache-2.0
# RaMstix boot script (boot.scr on the SD card's FAT partition, which the Overo's U-Boot
# runs first): the kernel and device tree from /boot of the root partition, the initramfs
# through Debian's /initrd.img link (U-Boot's ext4 follows it).
# Debian's kernel drives the OMAP UARTs with omap-serial (ttyO2) and has the MMC host and
# ext4 as modules (hence the initramfs). fdtfile: set it in U-Boot's environment or in
# uEnv.txt for an OMAP3530 Overo (omap3-overo-tobi.dtb); the DM3730 one is the default.
if test -z "${fdtfile}"; then setenv fdtfile omap3-overo-storm-tobi.dtb; fi
setenv bootargs "console=ttyO2,115200n8 root=/dev/mmcblk0p2 rw rootfstype=ext4 rootwait cpufreq.default_governor=performance ${optargs}"
load mmc 0:2 ${fdtaddr} /boot/${fdtfile}
load mmc 0:2 ${rdaddr} /initrd.img
setenv rdsize ${filesize}
load mmc 0:2 ${loadaddr} /boot/zImage
bootz ${loadaddr} ${rdaddr}:${rdsize} ${fdtaddr}
