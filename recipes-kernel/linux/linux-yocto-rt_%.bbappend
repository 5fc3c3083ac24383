# SPDX-License-Identifier: Apache-2.0
# RaMstix on linux-yocto-rt (PREEMPT_RT): same BSP as linux-yocto; spp picks
# bsp/ramstix/ramstix-preempt-rt.scc, which adds ktypes/preempt-rt and ccomm-rt.cfg.
# Select it with PREFERRED_PROVIDER_virtual/kernel = "linux-yocto-rt".
FILESEXTRAPATHS:prepend:ramstix := "${THISDIR}/files:"
require ramstix-kernel.inc
