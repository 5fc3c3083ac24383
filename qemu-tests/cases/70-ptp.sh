#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: one clock across the boards, the way a user sets it up: a <clock> section
# qemu-tests: in signals.xml (control grandmaster, software timestamping), the shipped
# qemu-tests: ccomm-ptp4l.service on both boards (ptp4l configured by ccommd --clock-config,
# qemu-tests: IEEE 802.3 over the bridge). Checks that ccommd reports the clock state
# qemu-tests: ptp4l has (planner: synced) and reports the sync error the slave measured
# qemu-tests: once locked (ptp4l's "master offset": rms and largest). Then the true one-way
# qemu-tests: latency (a control write to its read on the planner, aged by production
# qemu-tests: through stale_by="production") next to RTT/2 in the same run. The harness
# qemu-tests: puts the original signals.xml back afterwards.
# qemu-tests: timeout=300
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

SYNC_SECONDS=${QT_PTP_SECONDS:-20}   # samples taken once the slave is synced
LOCK_TIMEOUT=${QT_PTP_LOCK_TIMEOUT:-120}
CFG=/etc/ccomm/signals.xml
UNIT=/usr/share/ccomm/systemd/ccomm-ptp4l.service
OUT=$QT_WORK/ptp.json

for b in control planner; do
	check "$b: ptp4l (linuxptp) and the ccomm-ptp4l unit installed" vm "$b" "command -v ptp4l >/dev/null && test -f $UNIT"
done
vm control "test -f $UNIT" || finish
note "planner eth0: $(vm planner 'ethtool -T eth0 2>/dev/null | grep -i software | tr -s "\t\n " " "')"

# The signal whose one-way latency is measured: a double control writes, aged on the
# planner from its production (stale_by is local policy: the boards keep one config hash).
sig=$(vm control 'ccomm list' | awk 'NR > 1 && $5 == "control" && $3 == "double" {print $2; exit}')
back=$(vm planner 'ccomm list' | awk 'NR > 1 && $5 == "planner" && $3 == "double" {print $2; exit}')
for b in control planner; do
	vm "$b" "sed -i 's|</ccomm>|  <clock grandmaster=\"control\" timestamping=\"software\" sync_interval_log=\"-3\"/>\n</ccomm>|; \
s|<signal name=\"$sig\" |<signal name=\"$sig\" stale_by=\"production\" |' $CFG"
	check "$b: signals.xml with <clock> passes ccommd --check" vm "$b" "ccommd --config $CFG --check >/dev/null"
	check "$b: ccommd --clock-config gives ptp4l its role" \
		vm "$b" "ccommd --config $CFG --clock-config | grep -q '^priority1'"
	# --no-block: on an emulated board a restart can take longer than one agent command
	vm "$b" "cp $UNIT /etc/systemd/system/ && systemctl daemon-reload && systemctl --no-block restart ccomm-ptp4l ccommd"
done
active() { vm "$1" 'systemctl is-active -q ccomm-ptp4l && systemctl is-active -q ccommd'; }
for b in control planner; do
	if wait_until 90 active "$b"; then
		check "$b: ccomm-ptp4l and ccommd running" true
	else
		fail "$b: ccomm-ptp4l and ccommd not both running after 90 s"
		vm "$b" 'systemctl list-jobs --no-pager; systemctl status --no-pager ccomm-ptp4l ccommd | tail -n 20'
	fi
done
note "control: ptp4l's socket: $(vm control 'ls -l /var/run/ptp4l')"

clock_line() { vm "$1" 'ccomm stats 2>/dev/null | grep "^clock:"'; }
synced() { clock_line planner | grep -q '^clock: synced'; }
if wait_until "$LOCK_TIMEOUT" synced; then
	check "planner's ccommd: clock synced to control's (ptp4l over the bridge)" true
	note "control: $(clock_line control)"
	note "planner: $(clock_line planner)"
	sleep "$SYNC_SECONDS"
	# ptp4l's once-a-second summaries of its offsets from the master ("rms N max N freq
	# ... delay N", ns; with Sync faster than 1/s it prints these instead of each offset),
	# over the last SYNC_SECONDS, from its journal
	stats=$(vm planner "journalctl -u ccomm-ptp4l -o cat --no-pager | grep ' rms .* max .* freq' | tail -n $SYNC_SECONDS" |
		awk '{ for (i = 1; i < NF; i++) { if ($i == "rms") { r = $(i + 1); n++; s += r * r } if ($i == "max" && $(i + 1) > m) m = $(i + 1)
		                                   if ($i == "delay") { d += $(i + 1); nd++ } } }
		     END { if (n) printf "{\"seconds\":%d,\"offset_rms_ns\":%.0f,\"offset_max_ns\":%d,\"path_delay_ns\":%.0f}\n", n, sqrt(s / n), m, nd ? d / nd : 0 }')
	note "sync error over the last ${SYNC_SECONDS} s (ptp4l on planner; software timestamps on emulated boards): $stats"
	check "sync error measured from ptp4l's offsets" test -n "$stats"

	# One-way: control writes $sig at 100 Hz; the planner's ccommd stamps each value with
	# its production time on control (mapped through the PTP time base), so the read's age
	# at the planner is write -> read across the boards ("last hop" of --stages).
	frames_from_control() { vm planner 'ccomm stats --json' | jget "next(p['frames_rx'] for p in d['peers'] if p['name'] == 'control')"; }
	t_oneway=$(vm planner 'date +%s')
	f0=$(frames_from_control)
	vm_bg planner oneway "ccomm-latency --mode oneway --send $back --recv $sig -r 100 -d 8 --warmup 1 \
--prio 70 --stages /run/ccq-oneway.stages --label oneway" >/dev/null
	vm --timeout 60 control "ccomm-latency --mode oneway --send $sig --recv $back -r 100 -d 8 --warmup 1 --prio 70 \
--label oneway-control" >/dev/null 2>&1
	vm_bg_wait planner oneway 60 >/dev/null
	oneway=$(vm planner 'cut -f2 /run/ccq-oneway.stages' | sort -n |
		awk '{ v[n++] = $1 } END { if (n) printf "{\"count\":%d,\"p50_ns\":%d,\"p99_ns\":%d,\"max_ns\":%d}\n", n, v[int(n * 0.5)], v[int(n * 0.99)], v[n - 1] }')
	# frames whose production-aged values were judged by arrival instead (a clock not synced
	# at that moment): ccommd logs their count every 10 s; the run is 800 frames of $sig
	sleep 10
	by_arrival=$(vm planner "journalctl -u ccommd -o cat --no-pager --since @$t_oneway | grep 'judged by their arrival'" |
		awk '{ n += $1 } END { print n + 0 }')
	frames=$(( $(frames_from_control) - f0 ))  # the same window as the log lines: the run and 10 s after it
	# RTT/2 in the same run, same signals, same rate
	vm_bg planner echo "ccomm-latency --mode echo --send $back --recv $sig -r 100 -d 12 --prio 70" >/dev/null
	sleep 1
	rtt=$(vm --timeout 60 control "ccomm-latency --mode ping --send $sig --recv $back -r 100 -d 6 --warmup 1 --prio 70 \
--label rtt2" 2>/dev/null | grep -m1 '^{')
	vm_bg_stop planner echo >/dev/null
	note "write -> read age on the planner, control -> planner, 100 Hz: $oneway"
	note "RTT/2 in the same run: $rtt"
	note "of the $frames frames from control in that window, $((frames - by_arrival)) were aged from production" \
		"(both clocks synced: the true one-way latency, within both clocks' sync error above) and $by_arrival" \
		"from arrival (a clock not synced at that moment: ccomm's synced means within 1 ms of the master, which" \
		"these emulated boards' software timestamps keep only part of the time)"
	printf '{"sync":%s,"oneway":%s,"rtt2":%s,"frames":%s,"frames_aged_from_arrival":%s}\n' "${stats:-null}" \
		"${oneway:-null}" "${rtt:-null}" "${frames:-null}" "${by_arrival:-null}" >"$OUT"
	check "one-way latency measured; frames aged from their production on control while both clocks were synced" \
		test -n "$oneway" -a "$((frames - by_arrival))" -gt 0
else
	fail "planner's ccommd did not report a synced clock within ${LOCK_TIMEOUT} s ($(clock_line planner))"
	vm planner 'journalctl -u ccomm-ptp4l -o cat --no-pager | tail -n 20'
fi

for b in control planner; do
	vm "$b" "systemctl stop ccomm-ptp4l; rm -f /etc/systemd/system/ccomm-ptp4l.service; systemctl daemon-reload"
done
finish
