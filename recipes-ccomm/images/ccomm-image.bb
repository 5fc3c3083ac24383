# SPDX-License-Identifier: Apache-2.0
SUMMARY = "Console image for a board running ccommd"
DESCRIPTION = "Boots to a serial/SSH console with ccommd enabled, the ccomm CLI, \
               the unit tests (ccomm-ptest) and dropbear."
BUGTRACKER = "https://github.com/ccomm/ccomm/issues"
SECTION = "images"
LICENSE = "MIT"

inherit core-image

IMAGE_INSTALL = "packagegroup-core-boot \
                 ccomm \
                 ccomm-cli \
                 ${@bb.utils.contains('DISTRO_FEATURES', 'ptest', 'ccomm-ptest ptest-runner', '', d)} \
                 dropbear \
                 ${CORE_IMAGE_EXTRA_INSTALL} \
                 "
IMAGE_LINGUAS = ""

# ccommd and the CLI find their node in signals.xml by the hostname (unless --node or
# $CCOMM_NODE say otherwise), so the image's hostname is the board's node. Build the
# other board's image with CCOMM_NODE = "planner" (default signals.xml).
CCOMM_NODE ?= "control"
ROOTFS_POSTPROCESS_COMMAND += "ccomm_set_node"
ccomm_set_node[doc] = "Write the board's ccomm node name (CCOMM_NODE) to /etc/hostname"
ccomm_set_node() {
    echo "${CCOMM_NODE}" > ${IMAGE_ROOTFS}${sysconfdir}/hostname
}

# testimage: lib/oeqa/runtime/cases/ccomm.py checks the service and a signal round trip
TEST_SUITES ?= "ping ssh ccomm"
