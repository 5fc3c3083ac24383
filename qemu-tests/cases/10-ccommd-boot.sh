#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: ccommd runs on both boards right after boot, started by systemd from the
# qemu-tests: installed unit (enabled, no manual step, no restart), and each daemon sees
# qemu-tests: the other one as a live peer.
# qemu-tests: timeout=120
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

for b in $QT_BOARDS; do
	# Recorded by qemu-tests/run as soon as the board had booted, before any case ran.
	boot=$(vm "$b" 'cat /run/ccq/boot-state')
	note "$b: at boot: $(tr '\n' ' ' <<<"$boot")"
	check "$b: ccommd.service enabled" grep -qx 'UnitFileState=enabled' <<<"$boot"
	check "$b: ccommd active after boot, without a manual start" grep -qx 'ActiveState=active' <<<"$boot"
	check "$b: ccommd did not need a restart to come up" grep -qx 'NRestarts=0' <<<"$boot"
	check "$b: systemctl is-active ccommd" vm "$b" 'systemctl is-active -q ccommd'
	# The service notified readiness (Type=notify) and runs as the node named like the board.
	vm "$b" 'journalctl -b -u ccommd --no-pager -o cat | head -n 8' | sed "s/^/  $b journal: /"
	st=$(vm "$b" 'ccomm stats --json')
	check "$b: ccomm stats: node $b, daemon alive" \
		jcheck "d['node'] == '$b' and d['daemon_alive']" <<<"$st"
	check "$b: the peer is alive (heartbeats arrive)" \
		wait_until 10 eval "vm $b 'ccomm stats --json' | jcheck 'all(p[\"alive\"] for p in d[\"peers\"]) and len(d[\"peers\"]) == 1'"
done
finish
