# SPDX-License-Identifier: Apache-2.0
# The ccomm board image, one for every machine (qemuarm, ramstix): Debian bookworm with
# systemd, busybox, linuxptp and ccomm's packages from this repository; ccommd.service
# enabled (by its package), /etc/ccomm/signals.xml a conffile of ccommd. The kernel is
# the machine's Debian kernel (KERNEL_NAME); ccomm-kernel-check compares its config with
# the options the layer asks for (recipes-kernel/linux/files/ramstix-kmeta).
DESCRIPTION = "ccomm board image"
LICENSE = "Apache-2.0"
LIC_FILES_CHKSUM = "file://${CCOMM_TOPDIR}/LICENSE;md5=3b83ef96387f14655fc854ddc3c6bd57"
PV = "1.0"

inherit image

# The apt sources the image ships: Debian's own, with security updates, whatever mirror
# the build used (Isar replaces the build's lists with the .list files of SRC_URI).
SRC_URI += "file://debian.list"

IMAGE_INSTALL += "ccommd"
# The QEMU boards also run the latency floor programs (qemu-tests/cases/60-latency.sh).
IMAGE_INSTALL:append:qemuarm = " ccomm-bench"
# From Debian. The QEMU suite's tools: iproute2, procps, socat, ping, kmod.
IMAGE_PREINSTALL += "systemd systemd-sysv busybox linuxptp kmod iproute2 procps socat iputils-ping openssh-server"

# As the image from Debian's tools (meta-ccomm/image-debian/customize): root has no
# password ('*': none matches) and SSH takes keys only; none is published. The owner adds
# keys or a password hash before the first boot (docs/yocto.md, "First boot").
USERS += "root"
USER_root[password] = "*"
ROOTFS_POSTPROCESS_COMMAND += "ccomm_sshd_keys_only"
ccomm_sshd_keys_only() {
    sudo install -D -m 644 '${CCOMM_TOPDIR}/meta-ccomm/image-debian/rootfs/etc/ssh/sshd_config.d/ccomm.conf' \
        '${ROOTFSDIR}/etc/ssh/sshd_config.d/ccomm.conf'
}

# RaMstix: the Overo's U-Boot loads /boot/zImage and /boot/<fdtfile> from the root
# partition (docs/yocto.md): copies of Debian's kernel and device trees under those names
# (a kernel upgrade on the board needs them copied again). The initramfs, generated after
# this step, boot.scr loads through Debian's /initrd.img link.
ROOTFS_POSTPROCESS_COMMAND:append:ramstix = " ccomm_ramstix_boot_files"
ccomm_ramstix_boot_files() {
    sudo -s <<EOSUDO
        set -e
        kver=\$(ls '${ROOTFSDIR}/boot' | sed -n 's/^vmlinuz-//p' | sort -V | tail -n1)
        [ -n "\$kver" ]
        cp '${ROOTFSDIR}'/boot/vmlinuz-\$kver '${ROOTFSDIR}/boot/zImage'
        for dtb in ${RAMSTIX_DTBS}; do
            src=\$(find '${ROOTFSDIR}'/usr/lib/linux-image-\$kver -name \$dtb | head -n1)
            [ -n "\$src" ] || { echo "no \$dtb in linux-image-\$kver" >&2; exit 1; }
            cp "\$src" '${ROOTFSDIR}'/boot/\$dtb
        done
EOSUDO
}

# The initramfs only needs to find the root file system: the drivers for it, listed, not
# Debian's default MODULES=most (some 1000 modules, each copied through qemu-user in the
# build: minutes, and a larger initramfs on every boot).
CCOMM_INITRAMFS_MODULES = "ext4"
CCOMM_INITRAMFS_MODULES:append:qemuarm = " virtio_mmio virtio_blk"
CCOMM_INITRAMFS_MODULES:append:ramstix = " omap_hsmmc mmc_block"
ROOTFS_POSTPROCESS_COMMAND += "ccomm_initramfs_modules"
ccomm_initramfs_modules() {
    sudo -s <<EOSUDO
        set -e
        mkdir -p '${ROOTFSDIR}/etc/initramfs-tools/conf.d'
        echo MODULES=list >'${ROOTFSDIR}/etc/initramfs-tools/conf.d/ccomm-modules.conf'
        printf '%s\n' ${CCOMM_INITRAMFS_MODULES} >>'${ROOTFSDIR}/etc/initramfs-tools/modules'
EOSUDO
}

# Debian's linuxptp enables timemaster.service (ptp4l and an NTP daemon on one clock). On a
# ccomm board PTP comes from signals.xml's <clock> through ccomm-ptp4l.service (enabled by
# hand, docs/config.md); two stacks steering one clock fight, so timemaster stays off.
ROOTFS_POSTPROCESS_COMMAND += "ccomm_timemaster_off"
ccomm_timemaster_off() {
    sudo rm -f '${ROOTFSDIR}/etc/systemd/system/multi-user.target.wants/timemaster.service'
}
