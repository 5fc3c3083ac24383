# SPDX-License-Identifier: Apache-2.0
# ccomm boot script (boot.scr on the card's first, FAT partition). Runs under the card's own
# U-Boot (MLO + u-boot.img), under an Overo's factory U-Boot in NAND, and under any
# distro-boot U-Boot (devtype/devnum/distro_bootpart set by it; else mmc 0, partition 1).
# Kernel, initramfs and device tree come from the root partition (partition 2): /boot/zImage,
# Debian's /initrd.img link (its kernel has the MMC host and ext4 as modules; a root file
# system without /initrd.img, as Yocto's, boots without one), /boot/${fdtfile}.
#
# Overrides: uEnv.txt on the FAT partition, imported when present (name=value lines):
#   fdtfile      Linux device tree in /boot of partition 2. Default by SoC: the Overo Fire
#                (OMAP3530) omap3-overo-tobi.dtb, the Storm (DM3730; ccomm_soc=omap36xx,
#                which the card's U-Boot sets) omap3-overo-storm-tobi.dtb.
#   ccomm_fdt    "firmware": use the device tree the firmware passes at ${fdt_addr} (QEMU's
#                -M virt with u-boot-qemu) instead of a file; the kernel console then
#                follows that tree's stdout-path unless ccomm_console is set.
#   ccomm_console  console= of the kernel (default ttyO2,115200n8: UART3, Debian's armmp
#                kernel drives OMAP UARTs with omap-serial, CONFIG_SERIAL_OMAP).
#   ccomm_root   root= of the kernel (default PARTUUID of partition 2, else /dev/mmcblk0p2).
#   optargs      appended to the kernel command line.
if test -z "${devtype}"; then setenv devtype mmc; fi
if test -z "${devnum}"; then setenv devnum 0; fi
if test -z "${distro_bootpart}"; then setenv distro_bootpart 1; fi
if test -z "${kernel_addr_r}"; then setenv kernel_addr_r ${loadaddr}; fi
if test -z "${fdt_addr_r}"; then setenv fdt_addr_r ${fdtaddr}; fi
if test -z "${ramdisk_addr_r}"; then setenv ramdisk_addr_r ${rdaddr}; fi
# fdtfile comes from uEnv.txt or the SoC, never from the firmware's default environment
setenv fdtfile
if test -e ${devtype} ${devnum}:${distro_bootpart} uEnv.txt; then
	load ${devtype} ${devnum}:${distro_bootpart} ${ramdisk_addr_r} uEnv.txt
	env import -t ${ramdisk_addr_r} ${filesize}
	echo "ccomm: uEnv.txt imported"
fi
if test -z "${fdtfile}"; then
	if test "${ccomm_soc}" = "omap36xx"; then
		setenv fdtfile omap3-overo-storm-tobi.dtb
	else
		setenv fdtfile omap3-overo-tobi.dtb
	fi
fi
if test -z "${ccomm_root}"; then
	if part uuid ${devtype} ${devnum}:2 ccomm_partuuid; then
		setenv ccomm_root PARTUUID=${ccomm_partuuid}
	else
		setenv ccomm_root /dev/mmcblk0p2
	fi
fi
setenv ccomm_ok 1
if test "${ccomm_fdt}" = "firmware"; then
	if test -z "${fdt_addr}"; then
		echo "ccomm: ccomm_fdt=firmware, but the firmware set no fdt_addr: not booting"
		setenv ccomm_ok 0
	fi
	setenv ccomm_dt ${fdt_addr}
	setenv ccomm_dtname "device tree of the firmware at ${fdt_addr}"
else
	if test -z "${ccomm_console}"; then setenv ccomm_console ttyO2,115200n8; fi
	if test -e ${devtype} ${devnum}:2 /boot/${fdtfile}; then
		load ${devtype} ${devnum}:2 ${fdt_addr_r} /boot/${fdtfile}
		setenv ccomm_dt ${fdt_addr_r}
		setenv ccomm_dtname /boot/${fdtfile}
	else
		echo "ccomm: no device tree /boot/${fdtfile} on ${devtype} ${devnum}:2: not booting"
		echo "ccomm: set fdtfile in uEnv.txt to one in /boot of the root partition"
		setenv ccomm_ok 0
	fi
fi
if test -n "${ccomm_console}"; then setenv ccomm_conarg console=${ccomm_console}; else setenv ccomm_conarg; fi
if test "${ccomm_ok}" = "1"; then
	setenv bootargs "${ccomm_conarg} root=${ccomm_root} rw rootfstype=ext4 rootwait cpufreq.default_governor=performance ${optargs}"
	echo "ccomm: kernel /boot/zImage, ${ccomm_dtname}, root ${ccomm_root}"
	setenv ccomm_rd -
	if test -e ${devtype} ${devnum}:2 /initrd.img; then
		load ${devtype} ${devnum}:2 ${ramdisk_addr_r} /initrd.img
		setenv ccomm_rd ${ramdisk_addr_r}:${filesize}
	fi
	load ${devtype} ${devnum}:2 ${kernel_addr_r} /boot/zImage
	bootz ${kernel_addr_r} ${ccomm_rd} ${ccomm_dt}
	echo "ccomm: bootz failed"
fi
