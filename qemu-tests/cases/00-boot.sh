#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: both boards booted the same image with the same signals.xml and no per-board
# qemu-tests: name: systemd reached its target without failed units, each board has its
# qemu-tests: node's hostname and address (ccomm-board-net, by its MAC) and the real-time
# qemu-tests: kernel, and ccommd finds each board's node (ccommd --which-node); a file in
# qemu-tests: which no node is the board is a clear error. A board booted from the SD card
# qemu-tests: (--card) came through U-Boot and the card's boot.scr, root on the card.
# qemu-tests: timeout=120
. "$(dirname "$0")/../lib/common.sh"

for b in $QT_BOARDS; do
	# One request per board, one line per fact.
	mapfile -t f < <(vm "$b" 'hostname; systemctl is-system-running; ip -4 -o addr show dev eth0 | awk "{print \$4}";
cat /sys/class/net/eth0/address; uname -rv; systemd-analyze 2>/dev/null | head -n1;
systemctl --failed --no-legend --plain')
	# One image: the hostname is the node's, set at boot from signals.xml by the MAC.
	check "$b: the hostname is the node's name, $b (is '${f[0]}')" [ "${f[0]}" = "$b" ]
	which=$(vm "$b" 'ccommd --which-node -c /etc/ccomm/signals.xml 2>&1')
	check "$b: ccommd finds its node ($which)" eval "[[ \"\$which\" == '$b ('* ]]"
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
	if [ "$b" = "${QT_CARD_BOARD:-}" ]; then
		# Booted from the SD card: U-Boot ran the card's boot.scr (its lines on the serial
		# console), which loaded the card's kernel and gave it the card's root partition.
		cl=$(vm "$b" 'cat /proc/cmdline')
		note "$b: booted from the card: $cl"
		check "$b: U-Boot ran the card's boot.scr (its 'ccomm: kernel /boot/zImage' line on the console)" \
			grep -q 'ccomm: kernel /boot/zImage' "$QT_WORK/$b.console.log"
		check "$b: the root file system is the card's root partition (root=PARTUUID=)" grep -q 'root=PARTUUID=' <<<"$cl"
	fi
done
# A signals.xml in which no node is this board (other names, MACs and addresses): ccommd
# says so and what it tried.
b=${QT_BOARDS%% *}
out=$(vm "$b" "sed -e 's/ip=\"10\.42\.0\./ip=\"10.42.9./' -e 's/mac=\"52:54:00:42/mac=\"52:54:00:49/' \
	-e 's/\\bcontrol\\b/ctl9/g' -e 's/\\bplanner\\b/pln9/g' /etc/ccomm/signals.xml >/tmp/nomatch.xml;
ccommd --which-node -c /tmp/nomatch.xml 2>&1; echo rc=\$?")
note "$b: no node matches: $(head -c 300 <<<"$out")"
check "$b: a file with no node for this board is refused, naming what was tried" \
	eval "grep -q 'no node of /tmp/nomatch.xml is this board' <<<\"\$out\" && grep -q 'rc=1' <<<\"\$out\""
finish
