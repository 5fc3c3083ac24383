#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: send on the cycle (docs/usage.md, "Send on the cycle"): control sends a
# qemu-tests: periodic signal on a 10 ms cycle at phase 2 ms (<realtime send_cycle_us>),
# qemu-tests: first sleeping until each instant (launch_time="sleep"), then with launch
# qemu-tests: times (SO_TXTIME) held by an ETF qdisc under prio, set up with the
# qemu-tests: documented tc commands and the CAP_NET_ADMIN drop-in. In each mode the
# qemu-tests: departures of control's data frames (a packet socket on control: after the
# qemu-tests: qdisc) against the intended instants (txtime_departures): p50/p99/max/min.
# qemu-tests: Where the guest kernel cannot run ETF, says why (the tc/modprobe error).
# qemu-tests: The harness puts the original signals.xml back afterwards.
# qemu-tests: timeout=240
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

SECONDS_PER_MODE=${QT_TXTIME_SECONDS:-20}
CYCLE_US=10000 PHASE_US=2000
LEAD_US=${QT_TXTIME_LEAD_US:-5000}     # emulated boards wake late: a generous lead
DELTA_NS=${QT_TXTIME_DELTA_NS:-2000000} # ETF's delta: its own wake-up latency here
CFG=/etc/ccomm/signals.xml
DEP=/usr/libexec/ccomm/bench/txtime_departures
OUT=$QT_WORK/txtime.json
DROPIN=/etc/systemd/system/ccommd.service.d/80-txtime.conf

vm control "test -x $DEP" >/dev/null || skip "txtime_departures not in the image (ccomm-bench)"
# No PTP here: instants on CLOCK_MONOTONIC (the departures are judged on the same board).
for b in control planner; do vm "$b" 'systemctl stop ccomm-ptp4l 2>/dev/null; true'; done

# One periodic signal from control (hashed: on both boards); the cycle is control's local policy.
set_config() {  # $1: launch_time
	local b
	for b in control planner; do
		vm "$b" "cp /run/ccq/signals.xml.orig $CFG && \
sed -i 's|</ccomm>|  <signal name=\"txt_cycle\" type=\"double\" producer=\"control\" consumers=\"planner\" period_ms=\"10\"/>\n</ccomm>|; \
/<node name=\"control\"/,/<\\/node>/ s|<realtime |<realtime send_cycle_us=\"$CYCLE_US\" send_phase_us=\"$PHASE_US\" send_lead_us=\"$LEAD_US\" launch_time=\"$1\" |' $CFG && \
ccommd --config $CFG --check >/dev/null" || return 1
	done
}
restart() {
	local b
	for b in control planner; do vm "$b" 'systemctl daemon-reload; systemctl --no-block restart ccommd'; done
	for b in control planner; do wait_until 60 vm "$b" 'systemctl is-active -q ccommd' || return 1; done
	vm control 'ccomm pub txt_cycle 1.5' >/dev/null
	fresh() { vm planner 'ccomm echo txt_cycle --once' | grep -q fresh; }
	wait_until 30 fresh
}
counters() { vm control 'ccomm stats --json' | jget "' '.join(str(d['counters'].get(k, 0)) for k in ('cycle_rounds', 'cycle_late', 'cycle_etf_drops', 'send_errors'))"; }
measure() {  # $1: mode name; prints the departures line, more percentiles, the round counters
	local line before after
	before=$(counters)
	line=$(vm --timeout $((SECONDS_PER_MODE + 30)) control \
		"$DEP eth0 0x88B5 $CYCLE_US $PHASE_US mono $SECONDS_PER_MODE /run/ccq-txtime-$1.samples")
	after=$(counters)
	note "departures, $1: $line"
	vm control "cat /run/ccq-txtime-$1.samples" >"$QT_WORK/txtime-$1.samples"
	note "departures, $1, percentiles p1 p5 p25 p50 p75 p95 p99 (us): $(sort -n "$QT_WORK/txtime-$1.samples" |
		awk '{ v[n++] = $1 } END { split("1 5 25 50 75 95 99", p, " "); for (i = 1; i <= 7; i++) printf "%.0f ", v[int(n * p[i] / 100)] / 1000 }')"
	note "control, during the $1 run: rounds, late, ETF drops, send errors: $(echo "$before $after" |
		awk '{ printf "%d %d %d %d", $5 - $1, $6 - $2, $7 - $3, $8 - $4 }')"
	note "control: $(vm control 'ccomm stats | grep -E "^send cycle:"')"
	echo "$line" >"$QT_WORK/txtime-$1.txt"
}
as_json() { sed -n 's/^n=\([0-9]*\) late_us p50=\([-0-9.]*\) p99=\([-0-9.]*\) max=\([-0-9.]*\) min=\([-0-9.]*\) spread_us=\([-0-9.]*\)$/{"n":\1,"p50_us":\2,"p99_us":\3,"max_us":\4,"min_us":\5,"spread_us":\6}/p' "$1" 2>/dev/null; }

# 1. Sleep until each instant.
check "signals.xml with a send cycle (launch_time=sleep) passes ccommd --check" set_config sleep
check "ccommd restarted; planner reads control's periodic signal" restart
check "control's ccommd sleeps until each instant" vm control "ccomm stats | grep -q '^send cycle: sleeps until each instant (launch_time'"
measure sleep
check "departures measured (sleep)" grep -q '^n=[1-9]' "$QT_WORK/txtime-sleep.txt"

# 2. Launch times: the ETF qdisc as docs/usage.md sets it up, CAP_NET_ADMIN at start.
etf_err=$(vm control "modprobe sch_prio 2>&1 && modprobe sch_etf 2>&1 && \
tc qdisc replace dev eth0 root handle 100: prio bands 3 priomap 1 2 2 0 1 2 1 1 1 1 1 1 1 1 1 1 2>&1 && \
tc qdisc replace dev eth0 parent 100:1 etf clockid CLOCK_TAI delta $DELTA_NS 2>&1 && echo ETF-OK")
note "control: kernel $(vm control 'uname -r'): $(echo "$etf_err" | tr '\n' ' ')"
note "control qdiscs: $(vm control 'tc qdisc show dev eth0' | tr '\n' ' ')"
txtime=null
if echo "$etf_err" | grep -q ETF-OK; then
	vm control "mkdir -p ${DROPIN%/*} && printf '[Service]\nAmbientCapabilities=CAP_NET_RAW CAP_NET_ADMIN\nCapabilityBoundingSet=CAP_NET_RAW CAP_NET_ADMIN\n' >$DROPIN"
	check "signals.xml with launch_time=auto passes ccommd --check" set_config auto
	check "ccommd restarted with launch times; planner reads control's periodic signal" restart
	note "control: $(vm control 'journalctl -u ccommd -o cat --no-pager | grep "send cycle" | tail -n 1')"
	check "control's ccommd sends with launch times (SO_TXTIME, ETF)" \
		vm control "ccomm stats | grep -q '^send cycle: launch times'"
	measure txtime
	check "departures measured (txtime)" grep -q '^n=[1-9]' "$QT_WORK/txtime-txtime.txt"
	txtime=$(as_json "$QT_WORK/txtime-txtime.txt")
	vm control "rm -f $DROPIN; tc qdisc del dev eth0 root 2>/dev/null; systemctl daemon-reload"
else
	note "ETF cannot run on this guest: $(echo "$etf_err" | tr '\n' ' ')"
fi
sleep_json=$(as_json "$QT_WORK/txtime-sleep.txt")
printf '{"cycle_us":%d,"phase_us":%d,"lead_us":%d,"etf_delta_ns":%d,"seconds":%d,"sleep":%s,"txtime":%s}\n' \
	"$CYCLE_US" "$PHASE_US" "$LEAD_US" "$DELTA_NS" "$SECONDS_PER_MODE" "${sleep_json:-null}" \
	"${txtime:-null}" >"$OUT"
note "result: $(cat "$OUT")"
finish
