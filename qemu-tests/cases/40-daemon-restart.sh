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

# Writers at 100 Hz and readers sampling every 20 ms on both boards.
vm_bg control pub "ccomm pub $sig_cp 1.5 --rate 100 --count 100000" >/dev/null
vm_bg planner pub "ccomm pub $sig_pc 2.5 --rate 100 --count 100000" >/dev/null
check "before: planner reads $sig_cp fresh" arrives_fresh planner $sig_cp 1.5 10
check "before: control reads $sig_pc fresh" arrives_fresh control $sig_pc 2.5 10
vm_bg planner mon "ccomm echo $sig_cp --interval 20" >/dev/null
vm_bg control mon "ccomm echo $sig_pc --interval 20" >/dev/null
sleep 1

for b in control planner; do
	pid_before=$(vm "$b" 'systemctl show -p MainPID --value ccommd')
	check "restart ccommd on $b" vm "$b" 'systemctl restart ccommd'
	check "$b: ccommd active again (new process)" \
		eval "[ \"\$(vm $b 'systemctl is-active ccommd')\" = active ] && [ \"\$(vm $b 'systemctl show -p MainPID --value ccommd')\" != '$pid_before' ]"
	check "after restarting $b: planner reads $sig_cp fresh" \
		arrives_fresh planner $sig_cp 1.5 15
	check "after restarting $b: control reads $sig_pc fresh" \
		arrives_fresh control $sig_pc 2.5 15
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

# What the readers saw. Under emulation a 100 Hz writer's gaps exceed 20 ms now and
# then (short stale flickers); a daemon restart is an outage: a stale run reaching an
# age of 500 ms or more. Each restart (of the sender's or of the receiver's daemon)
# interrupts the flow, so each reader must see two outages, each followed by fresh.
outages() {
	awk '{ st = $3; age = $5; sub(/age_us=/, "", age); age += 0
	       if (st ~ /^stale/) { if (age > runmax) runmax = age; instale = 1 }
	       else if (st == "fresh") { if (instale && runmax >= 500000) { n++; list = list sprintf(" %.1fs", runmax / 1e6) } instale = 0; runmax = 0; fresh++ } }
	     END { printf "%d%s\n", n, (n ? " (oldest sample of each:" list ")" : "") }'
}
op=$(outages <<<"$mon_p")
oc=$(outages <<<"$mon_c")
note "planner's reader of $sig_cp: $(wc -l <<<"$mon_p") samples, outages ended by fresh values: $op"
note "control's reader of $sig_pc: $(wc -l <<<"$mon_c") samples, outages ended by fresh values: $oc"
check "planner's reader saw stale, then fresh, for each restart" test "${op%% *}" -ge 2
check "control's reader saw stale, then fresh, for each restart" test "${oc%% *}" -ge 2
check "no reader saw its signal go 'never' (the segment survives a daemon restart)" \
	eval "! grep -q ' never ' <<<\"\$mon_p\$mon_c\""
finish
