# SPDX-License-Identifier: Apache-2.0
SUMMARY = "Console image for a board running ccommd"
DESCRIPTION = "Boots to a serial/SSH console with ccommd enabled, the ccomm CLI, ccomm-fmu, \
               the unit tests (ccomm-ptest) and dropbear."
BUGTRACKER = "https://github.com/ccomm/ccomm/issues"
SECTION = "images"
LICENSE = "MIT"

inherit core-image

IMAGE_INSTALL = "packagegroup-core-boot \
                 ccomm \
                 ccomm-cli \
                 ccomm-fmu \
                 ${@bb.utils.contains('DISTRO_FEATURES', 'ptest', 'ccomm-ptest ptest-runner', '', d)} \
                 dropbear \
                 ${CORE_IMAGE_EXTRA_INSTALL} \
                 "
IMAGE_LINGUAS = ""

# One image for every board: ccommd finds its node in signals.xml by the hostname, else
# by the board's MAC or IP (docs/yocto.md). Set CCOMM_NODE only to pin an image to one
# board: it is then written to /etc/hostname.
CCOMM_NODE ?= ""
ROOTFS_POSTPROCESS_COMMAND += "ccomm_set_node"
ccomm_set_node[doc] = "Write CCOMM_NODE, if set, to /etc/hostname (the image then names its board)"
ccomm_set_node() {
    if [ -n "${CCOMM_NODE}" ]; then
        echo "${CCOMM_NODE}" > ${IMAGE_ROOTFS}${sysconfdir}/hostname
    fi
}

# testimage: lib/oeqa/runtime/cases/ccomm.py checks the service and a signal round trip
TEST_SUITES ?= "ping ssh ccomm"
