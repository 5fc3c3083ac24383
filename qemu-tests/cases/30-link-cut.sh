#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: cutting the control board's cable while signals flow both ways: readers
# qemu-tests: see them stale exactly when they are older than stale_after_ms (the safe
# qemu-tests: value where one is configured), the daemons count the peer down and the
# qemu-tests: stale transitions; after reconnecting everything is fresh again.
# qemu-tests: timeout=300
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

CUT_SECONDS=3
# A signal each way: the first double each board produces.
sig_cp=$(vm control 'ccomm list' | awk 'NR > 1 && $5 == "control" && $3 == "double" {print $2; exit}')
sig_pc=$(vm planner 'ccomm list' | awk 'NR > 1 && $5 == "planner" && $3 == "double" {print $2; exit}')
cfg=$(vm control 'cat /etc/ccomm/signals.xml')
attr() { grep -o "<$1 [^>]*" <<<"$cfg" | grep "${3:-.}" | grep -o "$2=\"[^\"]*\"" | head -n1 | cut -d'"' -f2; }
stale_cp=$(attr signal stale_after_ms "name=\"$sig_cp\"")
stale_pc=$(attr signal stale_after_ms "name=\"$sig_pc\"")
safe_pc=$(attr signal safe_value "name=\"$sig_pc\"")
peer_timeout=$(attr network peer_timeout_ms)
note "$sig_cp control -> planner (stale after ${stale_cp} ms), $sig_pc planner -> control (stale after ${stale_pc} ms, safe value ${safe_pc:-none}); peer timeout ${peer_timeout} ms"
[ -n "$sig_cp" ] && [ -n "$sig_pc" ] && [ -n "$stale_cp" ] && [ -n "$peer_timeout" ] || bail "cannot read the signals from the configuration"

status_of() { # BOARD SIGNAL -> "value status" from `ccomm echo --once`
	vm "$1" "ccomm echo $2 --once" | awk '{print $2, $3}'
}

cut_cycle() {
	local how=$1
	# 100 Hz writers on both boards for the whole cycle.
	vm_bg control pub "ccomm pub $sig_cp 1.5 --rate 100 --count 100000" >/dev/null
	vm_bg planner pub "ccomm pub $sig_pc 2.5 --rate 100 --count 100000" >/dev/null
	check "$how: before the cut: planner reads $sig_cp fresh" \
		arrives_fresh planner $sig_cp 1.5 10
	check "$how: before the cut: control reads $sig_pc fresh" \
		arrives_fresh control $sig_pc 2.5 10
	local before_p before_c
	before_p=$(vm planner 'ccomm stats --json')
	before_c=$(vm control 'ccomm stats --json')
	# A reader on the planner samples status and age every 10 ms across the cut.
	vm_bg planner mon "ccomm echo $sig_cp --interval 10" >/dev/null
	sleep 1
	link_down control "$how" || bail "cannot cut the link ($how)"
	local t0=$SECONDS
	check "$how: cut: planner reads $sig_cp stale" \
		wait_until 15 eval "[ \"\$(status_of planner $sig_cp | cut -d' ' -f2)\" = stale ]"
	local expect_pc="stale"
	[ -n "$safe_pc" ] && expect_pc="$safe_pc stale*"
	check "$how: cut: control reads $sig_pc as '$expect_pc'" \
		wait_until 15 eval "[ \"\$(status_of control $sig_pc)\" = '$expect_pc' ] || [ \"\$(status_of control $sig_pc | cut -d' ' -f2)\" = '$expect_pc' ]"
	sleep $((CUT_SECONDS - (SECONDS - t0) > 0 ? CUT_SECONDS - (SECONDS - t0) : 0))
	local cut_p cut_c
	cut_p=$(vm planner 'ccomm stats --json')
	cut_c=$(vm control 'ccomm stats --json')
	note "$how: during the cut: planner: $(peer_summary <<<"$cut_p"); $sig_cp: $(sig_summary "$sig_cp" <<<"$cut_p")"
	note "$how: during the cut: control: $(peer_summary <<<"$cut_c"); $sig_pc: $(sig_summary "$sig_pc" <<<"$cut_c")"
	check "$how: cut: both daemons report the peer down" \
		jcheck "not any(p['alive'] for p in d['peers'])" <<<"$cut_p"
	check "$how: cut: control's daemon reports the peer down" \
		jcheck "not any(p['alive'] for p in d['peers'])" <<<"$cut_c"
	check "$how: cut: planner counted a peer down transition" \
		[ "$(jget "sum(p['down_transitions'] for p in d['peers'])" <<<"$cut_p")" -gt "$(jget "sum(p['down_transitions'] for p in d['peers'])" <<<"$before_p")" ]
	check "$how: cut: planner counted $sig_cp going stale" \
		[ "$(jget "[s['stale_transitions'] for s in d['signals'] if s['name'] == '$sig_cp'][0]" <<<"$cut_p")" -gt \
		"$(jget "[s['stale_transitions'] for s in d['signals'] if s['name'] == '$sig_cp'][0]" <<<"$before_p")" ]

	link_up control "$how" || bail "cannot restore the link ($how)"
	check "$how: reconnected: planner reads $sig_cp fresh again" \
		arrives_fresh planner $sig_cp 1.5 10
	check "$how: reconnected: control reads $sig_pc fresh again" \
		arrives_fresh control $sig_pc 2.5 10
	check "$how: reconnected: both daemons see the peer alive" \
		wait_until 10 eval "vm planner 'ccomm stats --json' | jcheck 'all(p[\"alive\"] for p in d[\"peers\"])' && vm control 'ccomm stats --json' | jcheck 'all(p[\"alive\"] for p in d[\"peers\"])'"
	sleep 0.5
	local mon
	mon=$(vm_bg_stop planner mon)
	vm_bg_stop control pub >/dev/null
	vm_bg_stop planner pub >/dev/null
	# The contract, sample by sample: fresh while age <= stale_after_ms, stale after.
	# Lines: NAME VALUE STATUS seq=N age_us=A lost=L
	local n fresh stale first maxage back bad
	read -r n fresh stale first maxage back bad < <(awk -v lim=$((stale_cp * 1000)) '
		{ st = $3; age = $5; sub(/age_us=/, "", age); age += 0; n++
		  if (st == "stale") { stale++; if (age <= lim) bad++; if (age > maxage) maxage = age; if (first == "") first = age }
		  else if (st == "fresh") { fresh++; if (age > lim) bad++ }
		  if (prev == "stale" && st == "fresh") back++
		  prev = st }
		END { print n + 0, fresh + 0, stale + 0, first + 0, maxage + 0, back + 0, bad + 0 }' <<<"$mon")
	note "$how: planner's 10 ms samples of $sig_cp: $n samples, $fresh fresh, $stale stale (first stale one ${first} us old, oldest ${maxage} us), $back returns to fresh, $bad inconsistent"
	check "$how: every sample is stale exactly when older than ${stale_cp} ms" test "$n" -gt 0 -a "$bad" = 0
	check "$how: the samples saw the cut (stale for over 1 s) and the return to fresh" \
		test "$maxage" -ge 1000000 -a "$back" -ge 1
}

cut_cycle "$([ "$QT_NET" = netns ] && echo tap || echo carrier)"
# With the bridge, also cut the board's own carrier (QEMU link down): a different path
# in the board (the NIC reports no carrier) that must end the same way.
[ "$QT_NET" = netns ] && cut_cycle carrier
finish
