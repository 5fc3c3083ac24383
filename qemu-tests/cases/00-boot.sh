#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: both boards booted the image: systemd reached its target without failed
# qemu-tests: units, each board has its name, its address and the real-time kernel.
# qemu-tests: timeout=120
. "$(dirname "$0")/../lib/common.sh"

for b in $QT_BOARDS; do
	# One request per board, one line per fact.
	mapfile -t f < <(vm "$b" 'hostname; systemctl is-system-running; ip -4 -o addr show dev eth0 | awk "{print \$4}";
cat /sys/class/net/eth0/address; uname -rv; systemd-analyze 2>/dev/null | head -n1;
systemctl --failed --no-legend --plain')
	check "$b: hostname is $b (is '${f[0]}')" [ "${f[0]}" = "$b" ]
	check "$b: systemd state is running (is '${f[1]}')" [ "${f[1]}" = running ]
	[ "${f[1]}" = running ] && [ ${#f[@]} -le 6 ] || printf '  failed unit: %s\n' "${f[@]:6}"
	check "$b: eth0 has $(board_ip "$b")/24 (has '${f[2]}')" [ "${f[2]}" = "$(board_ip "$b")/24" ]
	check "$b: eth0 MAC is $(board_mac "$b")" [ "${f[3]}" = "$(board_mac "$b")" ]
	note "$b: kernel ${f[4]}"
	if [ "$QT_IMAGE_KIND" != external ]; then
		# The Debian test image boots Debian's PREEMPT_RT kernel (linux-image-rt-armmp).
		check "$b: PREEMPT_RT kernel" grep -q PREEMPT_RT <<<"${f[4]}"
	fi
	note "$b: ${f[5]}"
done
finish
