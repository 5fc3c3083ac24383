#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: `systemctl restart ccommd` on one board, then the other, while
# qemu-tests: applications write and read on both: the readers see the signals go
# qemu-tests: stale, then fresh again; no application stops or needs a restart.
# qemu-tests: timeout=300
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

sig_cp=$(vm control 'ccomm list' | awk 'NR > 1 && $5 == "control" && $3 == "double" {print $2; exit}')
sig_pc=$(vm planner 'ccomm list' | awk 'NR > 1 && $5 == "planner" && $3 == "double" {print $2; exit}')
[ -n "$sig_cp" ] && [ -n "$sig_pc" ] || bail "cannot read the signals"
status_of() { vm "$1" "ccomm echo $2 --once" | awk '{print $2, $3}'; }

# Writers at 100 Hz and readers sampling every 10 ms on both boards.
vm_bg control pub "ccomm pub $sig_cp 1.5 --rate 100 --count 100000" >/dev/null
vm_bg planner pub "ccomm pub $sig_pc 2.5 --rate 100 --count 100000" >/dev/null
check "before: planner reads $sig_cp fresh" wait_until 10 eval "[ \"\$(status_of planner $sig_cp)\" = '1.5 fresh' ]"
check "before: control reads $sig_pc fresh" wait_until 10 eval "[ \"\$(status_of control $sig_pc)\" = '2.5 fresh' ]"
vm_bg planner mon "ccomm echo $sig_cp --interval 10" >/dev/null
vm_bg control mon "ccomm echo $sig_pc --interval 10" >/dev/null
sleep 1

for b in control planner; do
	pid_before=$(vm "$b" 'systemctl show -p MainPID --value ccommd')
	check "restart ccommd on $b" vm "$b" 'systemctl restart ccommd'
	check "$b: ccommd active again (new process)" \
		eval "[ \"\$(vm $b 'systemctl is-active ccommd')\" = active ] && [ \"\$(vm $b 'systemctl show -p MainPID --value ccommd')\" != '$pid_before' ]"
	check "after restarting $b: planner reads $sig_cp fresh" \
		wait_until 15 eval "[ \"\$(status_of planner $sig_cp)\" = '1.5 fresh' ]"
	check "after restarting $b: control reads $sig_pc fresh" \
		wait_until 15 eval "[ \"\$(status_of control $sig_pc)\" = '2.5 fresh' ]"
	sleep 1
done

for b in control planner; do
	check "$b: the writer and the reader application are still running" \
		vm "$b" 'systemctl is-active -q ccq-pub ccq-mon'
done
mon_p=$(vm_bg_stop planner mon)
mon_c=$(vm_bg_stop control mon)
vm_bg_stop control pub >/dev/null
vm_bg_stop planner pub >/dev/null

# What the readers saw: runs of one status, e.g. "fresh stale fresh stale fresh".
runs() { awk '$3 != prev {printf "%s%s", (n++ ? " " : ""), $3; prev = $3} END {print ""}'; }
rp=$(runs <<<"$mon_p")
rc=$(runs <<<"$mon_c")
note "planner's reader of $sig_cp: $(wc -l <<<"$mon_p") samples: $rp"
note "control's reader of $sig_pc: $(wc -l <<<"$mon_c") samples: $rc"
# Each restart (of the sender's or of the receiver's daemon) interrupts both directions.
check "planner's reader saw stale, then fresh, for each restart" grep -Eq 'fresh stale.* fresh stale.* fresh$' <<<"$rp"
check "control's reader saw stale, then fresh, for each restart" grep -Eq 'fresh stale.* fresh stale.* fresh$' <<<"$rc"
check "no reader saw its signal go 'never' (the segment survives a daemon restart)" \
	eval "! grep -q ' never ' <<<\"\$mon_p\$mon_c\""
finish
