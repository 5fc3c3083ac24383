#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: the boards share an Ethernet segment: IP (ARP + ICMP) works both ways and
# qemu-tests: raw frames of ccomm's EtherType 0x88B5 sent on an AF_PACKET socket arrive.
# qemu-tests: timeout=120
. "$(dirname "$0")/../lib/common.sh"

check "control -> planner: ping" vm control "ping -c 3 -i 0.2 -W 2 $(board_ip planner) >/dev/null"
check "planner -> control: ping" vm planner "ping -c 3 -i 0.2 -W 2 $(board_ip control) >/dev/null"

# One raw frame: destination MAC, source MAC, EtherType 0x88B5, payload. socat's
# INTERFACE address is a PF_PACKET raw socket: each write is one frame, each read one
# received frame (all EtherTypes, so the check looks for the exact bytes).
mac_octal() { local o=; for x in ${1//:/ }; do o+=$(printf '\\%03o' $((16#$x))); done; echo "$o"; }
hex() { od -An -v -tx1 | tr -d ' \n'; }

raw_frame_crosses() {
	local from=$1 to=$2 marker
	marker=ccomm-qemu-$from-$RANDOM$RANDOM-padding-to-the-ethernet-minimum
	vm_bg "$to" rawrx "timeout 15 socat -u INTERFACE:eth0 STDOUT > /run/ccq-rawrx.bin" >/dev/null || return 1
	sleep 1 # let the receiver open its socket
	# Broadcast and unicast, repeated: one lost frame must not decide the test.
	local dst
	for dst in ff:ff:ff:ff:ff:ff "$(board_mac "$to")"; do
		vm "$from" "for i in 1 2 3; do printf '$(mac_octal "$dst")$(mac_octal "$(board_mac "$from")")\\210\\265$marker' | socat -u STDIN INTERFACE:eth0; sleep 0.2; done" || return 1
	done
	sleep 1
	vm_bg_stop "$to" rawrx >/dev/null
	local want got
	want=$(printf '%s' "$(board_mac "$from" | tr -d :)88b5")$(printf '%s' "$marker" | hex)
	got=$(vm "$to" 'od -An -v -tx1 /run/ccq-rawrx.bin | tr -d " \n"')
	local n
	n=$(grep -o "$want" <<<"$got" | wc -l)
	note "$from -> $to: $n of 6 raw 0x88B5 frames received"
	[ "$n" -ge 1 ]
}
check "control -> planner: raw 0x88B5 frames" raw_frame_crosses control planner
check "planner -> control: raw 0x88B5 frames" raw_frame_crosses planner control
finish
