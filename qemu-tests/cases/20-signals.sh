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
ccommd --check /run/ccq/signals-$t.xml >/dev/null
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
# A signal with a safe value reads as that safe value once stale (20 ms after the
# write): those are checked while FROM keeps writing them at 100 Hz.
values_arrive() {
	local from=$1 to=$2 base=$3 cmds= i=0 s
	declare -A want
	for s in ${PRODUCES[$from]}; do
		i=$((i + 1))
		want[$s]=$base$i.25
		cmds+="ccomm pub $s ${want[$s]} || echo 'pub $s failed'; "
	done
	vm "$from" "$cmds" || return 1
	sleep 0.5
	local list bad=0 again= row
	list=$(vm "$to" 'ccomm list')
	for s in ${PRODUCES[$from]}; do
		row=$(awk -v s="$s" '$2 == s' <<<"$list")
		[ "$(awk '{print $8}' <<<"$row")" = "${want[$s]}" ] && continue
		if [[ $(awk '{print $6}' <<<"$row") == stale* ]]; then
			again+=" $s"
		else
			echo "  $to: $s: want ${want[$s]}, have: $row"
			bad=$((bad + 1))
		fi
	done
	if [ -n "$again" ]; then
		# Arrival-driven: while FROM rewrites these values at 20 Hz, a reader on TO waits
		# for the next updates of each signal in turn (one reader at a time: on a loaded
		# emulated board concurrent readers wake too late to see a 20 ms freshness).
		local job= s2 out
		for s in $again; do job+="ccomm pub $s ${want[$s]} --rate 20 --count 400 & "; done
		vm_bg "$from" values "$job wait" >/dev/null
		sleep 1
		out=$(vm --timeout 120 "$to" "for s in $again; do ccomm echo \$s -n 4 --timeout 10 | tail -n 3; done")
		local job_out
		job_out=$(vm_bg_stop "$from" values)
		for s in $again; do
			if ! awk -v s="$s" -v want="${want[$s]} fresh" '$1 == s && $2 " " $3 == want {ok = 1} END {exit !ok}' <<<"$out"; then
				echo "  $to: $s: never arrived fresh as ${want[$s]}: $(awk -v s="$s" '$1 == s' <<<"$out" | tr '\n' ';')"
				bad=$((bad + 1))
				s2=1
			fi
		done
		[ -z "${s2:-}" ] || sed 's/^/  writer: /' <<<"$job_out" | head -n 20
		note "$from -> $to: $(wc -w <<<"$again") signals with a safe value checked on arrival"
	fi
	note "$from -> $to: $((i - bad)) of $i values arrived exactly"
	[ "$bad" = 0 ] && [ "$i" -gt 0 ]
}

# A 100 Hz stream of N writes one way and of N the other way at the same time. Exact
# accounting: every write reaches the other daemon, in a frame of its own or merged
# into a later one (coalesced), none lost; and the reading application sees the updates
# arrive fresh.
N=200
counters() { # SIGNAL < JSON -> "writes coalesced rx lost"
	jget "(lambda s: '%d %d %d %d' % (s['writes'], s['coalesced'], s['rx'], s['lost']))([s for s in d['signals'] if s['name'] == '$1'][0])"
}
frames_lost() { jget "sum(p['frames_lost'] for p in d['peers'])"; }
streams_arrive() {
	local t=$1 ok=1 from to sig
	declare -A b4 sig_of
	sig_of[control]=$(awk '{print $1}' <<<"${PRODUCES[control]}")
	sig_of[planner]=$(awk '{print $1}' <<<"${PRODUCES[planner]}")
	for b in $QT_BOARDS; do b4[$b]=$(vm "$b" 'ccomm stats --json'); done
	vm_bg planner echo "ccomm echo ${sig_of[control]} -n 20 --timeout 60" >/dev/null
	vm_bg control echo "ccomm echo ${sig_of[planner]} -n 20 --timeout 60" >/dev/null
	sleep 1
	vm_bg control pub "ccomm pub ${sig_of[control]} 7 --rate 100 --count $N" >/dev/null
	vm_bg planner pub "ccomm pub ${sig_of[planner]} 9 --rate 100 --count $N" >/dev/null
	for b in $QT_BOARDS; do vm_bg_wait "$b" pub 60 >/dev/null || { echo "  $b: ccomm pub failed"; ok=0; }; done
	sleep 1
	declare -A now
	for b in $QT_BOARDS; do now[$b]=$(vm "$b" 'ccomm stats --json'); done
	for from in control planner; do
		to=$([ $from = control ] && echo planner || echo control)
		sig=${sig_of[$from]}
		local w0 c0 w1 c1 x r0 l0 r1 l1 fresh rc
		read -r w0 c0 x x < <(counters "$sig" <<<"${b4[$from]}")
		read -r w1 c1 x x < <(counters "$sig" <<<"${now[$from]}")
		read -r x x r0 l0 < <(counters "$sig" <<<"${b4[$to]}")
		read -r x x r1 l1 < <(counters "$sig" <<<"${now[$to]}")
		local flost=$(($(frames_lost <<<"${now[$to]}") - $(frames_lost <<<"${b4[$to]}")))
		local out
		out=$(vm_bg_wait "$to" echo 60); rc=$?
		fresh=$(grep -c " fresh " <<<"$out")
		note "$t: $sig $from -> $to: written $((w1 - w0)), coalesced by the sender $((c1 - c0)), received $((r1 - r0)), lost $((l1 - l0)), frames lost $flost; the reader saw $fresh of 20 updates fresh (exit $rc)"
		[ $((w1 - w0)) = "$N" ] || { echo "  $from wrote $((w1 - w0)) of $N"; ok=0; }
		[ $((r1 - r0 + c1 - c0)) = "$N" ] || { echo "  received + coalesced != written"; ok=0; }
		[ $((l1 - l0)) = 0 ] && [ "$flost" = 0 ] || ok=0
		[ "$rc" = 0 ] && [ "$fresh" -ge 15 ] || ok=0
	done
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
	check "$t: $N-update streams both ways at 100 Hz: every write accounted for, none lost, reader sees them fresh" streams_arrive $t
done
use_transport raw >/dev/null || true
finish
