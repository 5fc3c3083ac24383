#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: the thesis setup-simulation (36 doubles control -> planner, 9 back) flows
# qemu-tests: both ways through ccommd, over raw Ethernet and over UDP, driven with the
# qemu-tests: CLI: every signal arrives with its exact value, streams arrive complete.
# qemu-tests: timeout=420
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

# The signals each board produces, from the board's own configuration (ccomm list:
# ID NAME TYPE KIND PRODUCER STATUS AGE VALUE).
declare -A PRODUCES
for b in $QT_BOARDS; do
	PRODUCES[$b]=$(vm "$b" 'ccomm list' | awk -v b="$b" 'NR > 1 && $5 == b && $3 == "double" {print $2}' | tr '\n' ' ')
done
n_control=$(wc -w <<<"${PRODUCES[control]}")
n_planner=$(wc -w <<<"${PRODUCES[planner]}")
note "control produces $n_control doubles, planner $n_planner"
check "setup-simulation: 36 doubles control -> planner, 9 back" test "$n_control" = 36 -a "$n_planner" = 9

# use_transport raw|udp: the same configuration with every node on that transport,
# validated, installed on both boards, daemons restarted; waits for the peers.
use_transport() {
	local t=$1 b
	for b in $QT_BOARDS; do
		vm "$b" "set -e
sed 's/transport=\"[a-z]*\"/transport=\"$t\"/' /run/ccq/signals.xml.orig >/run/ccq/signals-$t.xml
ccommd --check /run/ccq/signals-$t.xml
cp /run/ccq/signals-$t.xml /etc/ccomm/signals.xml
systemctl restart ccommd" || return 1
	done
	for b in $QT_BOARDS; do
		wait_until 15 eval "vm $b 'ccomm stats --json' | jcheck 'd[\"daemon_alive\"] and all(p[\"alive\"] for p in d[\"peers\"])'" || return 1
	done
}

# The socket ccommd really uses: a packet socket for EtherType 0x88B5, or UDP 47800.
uses_transport() {
	local b=$1 t=$2
	if [ "$t" = raw ]; then
		vm "$b" 'awk "NR > 1 && tolower(\$4) == \"88b5\"" /proc/net/packet | grep -q .'
	else
		vm "$b" 'grep -qi ":BAB8 " /proc/net/udp' # 47800 = 0xBAB8
	fi
}

# Publishes one distinct value per signal on FROM, then checks every value on TO.
values_arrive() {
	local from=$1 to=$2 base=$3 cmds= i=0 s
	declare -A want
	for s in ${PRODUCES[$from]}; do
		i=$((i + 1))
		want[$s]=$base$i.25
		cmds+="ccomm pub $s ${want[$s]} || echo 'pub $s failed'; "
	done
	vm "$from" "$cmds" || return 1
	nap_host 0.5
	local list bad=0
	list=$(vm "$to" 'ccomm list')
	for s in ${PRODUCES[$from]}; do
		local row
		row=$(awk -v s="$s" '$2 == s' <<<"$list")
		# STATUS is stale by now (stale_after_ms=20 and no new write), the value stays.
		if [ "$(awk '{print $8}' <<<"$row")" != "${want[$s]}" ]; then
			echo "  $to: $s: want ${want[$s]}, have: $row"
			bad=$((bad + 1))
		fi
	done
	note "$from -> $to: $((i - bad)) of $i values arrived exactly"
	[ "$bad" = 0 ] && [ "$i" -gt 0 ]
}

# A 100 Hz stream of N writes one way and of N the other way at the same time: the
# consumer's `ccomm echo` must see every update fresh; no frame may be lost.
N=200
streams_arrive() {
	local t=$1 ok=0
	local sig_cp sig_pc
	sig_cp=$(awk '{print $1}' <<<"${PRODUCES[control]}")
	sig_pc=$(awk '{print $1}' <<<"${PRODUCES[planner]}")
	local before_p before_c
	before_p=$(vm planner 'ccomm stats --json')
	before_c=$(vm control 'ccomm stats --json')
	vm_bg planner echo "ccomm echo $sig_cp -n $N --timeout 30" >/dev/null
	vm_bg control echo "ccomm echo $sig_pc -n $N --timeout 30" >/dev/null
	nap_host 1
	vm_bg control pub "ccomm pub $sig_cp 7 --rate 100 --count $((N + 20))" >/dev/null
	vm_bg planner pub "ccomm pub $sig_pc 9 --rate 100 --count $((N + 20))" >/dev/null
	local out_p out_c rc_p rc_c
	out_p=$(vm_bg_wait planner echo 40); rc_p=$?
	out_c=$(vm_bg_wait control echo 40); rc_c=$?
	vm_bg_wait control pub 20 >/dev/null
	vm_bg_wait planner pub 20 >/dev/null
	local fresh_p fresh_c
	fresh_p=$(grep -c " fresh " <<<"$out_p")
	fresh_c=$(grep -c " fresh " <<<"$out_c")
	note "$t: planner saw $fresh_p fresh updates of $sig_cp (echo exit $rc_p), control $fresh_c of $sig_pc (exit $rc_c)"
	local after_p after_c
	after_p=$(vm planner 'ccomm stats --json')
	after_c=$(vm control 'ccomm stats --json')
	note "$t: planner $sig_cp: $(sig_summary "$sig_cp" <<<"$after_p")"
	note "$t: control $sig_pc: $(sig_summary "$sig_pc" <<<"$after_c")"
	note "$t: peers: planner sees $(jget "[(p['frames_rx'], p['frames_lost']) for p in d['peers']]" <<<"$after_p") (frames rx, lost), control $(jget "[(p['frames_rx'], p['frames_lost']) for p in d['peers']]" <<<"$after_c")"
	local lost
	lost=$(( $(jget "sum(p['frames_lost'] for p in d['peers'])" <<<"$after_p") - $(jget "sum(p['frames_lost'] for p in d['peers'])" <<<"$before_p") +
		$(jget "sum(p['frames_lost'] for p in d['peers'])" <<<"$after_c") - $(jget "sum(p['frames_lost'] for p in d['peers'])" <<<"$before_c") ))
	[ "$rc_p" = 0 ] && [ "$rc_c" = 0 ] && [ "$fresh_p" -ge $((N * 9 / 10)) ] && [ "$fresh_c" -ge $((N * 9 / 10)) ] && ok=1
	[ "$lost" = 0 ] || { echo "  $t: $lost frames lost during the streams"; ok=0; }
	[ $ok = 1 ]
}

nap_host() { sleep "$1"; }

for t in raw udp; do
	if ! use_transport $t; then
		fail "$t: configure both boards and see the peer alive"
		continue
	fi
	check "$t: control uses the $t socket" uses_transport control $t
	check "$t: planner uses the $t socket" uses_transport planner $t
	base=$([ $t = raw ] && echo 1 || echo 2)
	check "$t: 36 values control -> planner" values_arrive control planner "$base"
	check "$t: 9 values planner -> control" values_arrive planner control "$base"
	check "$t: $N-update streams both ways at 100 Hz, all fresh, no frame lost" streams_arrive $t
done
use_transport raw >/dev/null || true
finish
