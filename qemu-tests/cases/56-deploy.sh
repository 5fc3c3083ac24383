#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# qemu-tests: ccomm deploy from the host onto both boards while values flow: a file with
# qemu-tests: one more signal (a new config hash) is staged and checked on each board, then
# qemu-tests: each board's ccommd is armed with it and switches inside itself at one instant
# qemu-tests: (ccommd --reload PID --at T); the time the boards disagreed is measured from
# qemu-tests: frames_wrong_hash and the journals; then a file the planner refuses changes no board.
# qemu-tests: The transport is the test agent (vmctl run) where a lab uses ssh.
# qemu-tests: timeout=420
. "$(dirname "$0")/../lib/common.sh"
need_ccomm

CCOMMD=$QT_REPO/build/release/bin/ccommd
DEPLOY=$QT_REPO/python/src/ccomm/deploy.py
[ -x "$CCOMMD" ] || { echo "SKIP: no host ccommd at $CCOMMD (scripts/build release) for deploy's own check"; exit $KSFT_SKIP; }
W=$QT_WORK/deploy
mkdir -p "$W"
vm control 'cat /run/ccq/signals.xml.orig' >"$W/orig.xml" || bail "cannot read the configuration"
sig=$(grep '<signal ' "$W/orig.xml" | grep 'producer="control"' | grep 'consumers="[^"]*planner' | grep 'type="double"' |
	head -n1 | grep -o 'name="[^"]*"' | cut -d'"' -f2)
[ -n "$sig" ] || bail "no double control -> planner in the configuration"
sed 's|</ccomm>|  <signal name="deploy_probe" type="double" producer="control" consumers="planner"/>\n</ccomm>|' \
	"$W/orig.xml" >"$W/new.xml"
hb=$("$CCOMMD" -c "$W/new.xml" --check --json | "$CCOMM_PYTHON" -c 'import json,sys; print(json.load(sys.stdin)["network"]["heartbeat_ms"])')
deploy() {
	"$CCOMM_PYTHON" "$DEPLOY" "$@" --json --ccommd "$CCOMMD" --via "$CCOMM_PYTHON $QT_VMCTL run {host} --timeout 120 --" \
		--host "control=$QT_CTL_control" --host "planner=$QT_CTL_planner" --margin 4 --timeout 120
}
wrong_hash() { vm "$1" 'ccomm stats --json' | "$CCOMM_PYTHON" -c 'import json,sys; print(json.load(sys.stdin)["counters"]["frames_wrong_hash"])'; }

# Values flow throughout: control publishes $sig at 20 Hz (ccomm pub ends when its segment
# is retired by the switch; the loop starts it again, as an application reopens).
vm_bg control deploy-pub "i=0; while [ \$i -lt 400 ]; do i=\$((i + 1)); ccomm pub $sig \$i --rate 20 --count 100000 >/dev/null 2>&1; sleep 0.2; done"
# arriving: the planner's application receives new updates of $sig, fresh on arrival.
# Arrival-driven, not "is it fresh now": the 20 Hz writer's 50 ms gaps exceed the signal's
# stale_after_ms (20 ms in the test configuration), so a sample is stale most of the time.
arriving() {
	vm --timeout 25 planner "ccomm echo $sig -n 3 --timeout 15" >"$W/echo.out" 2>&1 &&
		tail -n 2 "$W/echo.out" | awk '$3 == "fresh" {ok = 1} END {exit !ok}'
}
flowing() {  # flowing SECONDS: arriving within SECONDS, else the last echo's output
	wait_until "$1" arriving && return 0
	sed 's/^/  echo: /' "$W/echo.out"
	return 1
}
check "before: $sig flows control -> planner" flowing 60
declare -A wh0
for b in control planner; do wh0[$b]=$(wrong_hash $b); done
since=$(vm control 'date +%s')

# 1. The deploy.
deploy "$W/new.xml" >"$W/deploy.json" 2>"$W/deploy.err"
drc=$?
sed 's/^/  deploy: /' "$W/deploy.err"
check "ccomm deploy exits 0 (every board switched)" test "$drc" = 0
for b in control planner; do
	check "$b: the new file is in place and reloaded" \
		vm $b "grep -q deploy_probe /etc/ccomm/signals.xml && test ! -e /etc/ccomm/signals.xml.staged && systemctl is-active -q ccommd"
done
check "after: the peers hear each other on the new configuration" \
	wait_until 20 eval "vm control 'ccomm stats --json' | jcheck 'all(p[\"alive\"] for p in d[\"peers\"])'"
check "after: $sig flows again" flowing 30
check "after: the new signal deploy_probe is known on the planner" eval "vm planner 'ccomm list' | grep -q deploy_probe"
declare -A wh
for b in control planner; do wh[$b]=$(( $(wrong_hash $b) - ${wh0[$b]} )); done
# The journals' "reloaded" lines, on the host's clock (deploy measured each board's offset).
"$CCOMM_PYTHON" - "$W/deploy.json" "$hb" "${wh[control]}" "${wh[planner]}" >"$W/disagree.txt" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
hb, wc, wp = int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
if any(x["applied_ns"] is None for x in d["boards"]):
    sys.exit("no switch times: " + "; ".join("%s %s %s" % (x["node"], x["state"], x["why"]) for x in d["boards"]))
spread = (max(x["applied_ns"] for x in d["boards"]) - min(x["applied_ns"] for x in d["boards"])) / 1e6
err = max(x["offset_error_ns"] for x in d["boards"]) / 1e6
agree = max(x["agree_error_ns"] for x in d["boards"]) / 1e6
print("%.1f %d" % (agree, hb))
print("the answers of both ccommd %.1f ms apart on the host's clock (offsets to the host +-%.1f ms; the boards' "
      "clocks against each other +-%.2f ms, %s; heartbeat %d ms); frames_wrong_hash: control %d, planner %d; "
      "each board's check took %s ms" % (
          spread, err, agree, ", ".join("%s: %s" % (x["node"], x["clock_source"]) for x in d["boards"]), hb, wc, wp,
          "/".join("%.0f" % (x["check_ns"] / 1e6) for x in d["boards"])))
PY
read -r off_err _ <"$W/disagree.txt"
note "disagreement: $(tail -n 1 "$W/disagree.txt")"
# Disagreeing boards drop each other's frames as frames_wrong_hash: control's values (20 Hz)
# at the planner, the planner's heartbeats at control. One heartbeat's worth, and one more
# at each edge, is the bound.
lim_p=$(( hb / 50 + 2 )) lim_c=2
check "the switch was measured: ccomm deploy gave both boards' answer times" test "$drc" = 0 -a -s "$W/disagree.txt"
# Each ccommd switches inside itself at the instant on its own clock (its journal: "at the
# agreed instant + X ms"); how far apart the boards switch is how well deploy knows their
# clocks against each other: from ccomm's own frames (the peers' clock floors, half the
# fastest round trip), not the test agent's round trip (hundreds of ms under emulation).
# The bound is checked where that is under one heartbeat (else the boards' clocks are
# unknown to deploy, a known gap).
bound="the boards disagreed at most one heartbeat: frames_wrong_hash planner ${wh[planner]} <= $lim_p, control ${wh[control]} <= $lim_c"
if awk -v e="$off_err" -v h="$hb" 'BEGIN {exit !(e < h)}'; then
	check "$bound" test "$drc" = 0 -a "${wh[planner]}" -le "$lim_p" -a "${wh[control]}" -le "$lim_c"
else
	known "$bound" "the boards' clocks against each other are known to +-$off_err ms only, more than one heartbeat" \
		test "$drc" = 0 -a "${wh[planner]}" -le "$lim_p" -a "${wh[control]}" -le "$lim_c"
fi
for b in control planner; do
	vm $b "journalctl -u ccommd --since @$since --no-pager -o short-unix | grep -m1 'reloaded /etc/ccomm/signals.xml (from'" |
		sed "s/^/  $b journal: /"
done

# 2. A file the planner refuses: it puts the planner's node on eth9, an interface that
# board does not have (control's own check passes it): deploy exits 1, names the planner
# and why, and no board changes.
sed '/<node name="planner"/s|interface="[^"]*"|interface="eth9"|' "$W/orig.xml" >"$W/refused.xml"
sums() { for b in control planner; do vm $b 'sha256sum /etc/ccomm/signals.xml' | cut -d' ' -f1; done; }
before=$(sums)
deploy "$W/refused.xml" >"$W/refused.json" 2>"$W/refused.err"
rc=$?
sed 's/^/  deploy: /' "$W/refused.err"
check "a file the planner refuses: exit 1" test "$rc" = 1
check "  ... deploy names the planner and why" grep -q "planner refused: .*interface eth9" "$W/refused.err"
check "  ... no board changed (files as before, nothing staged)" \
	eval "[ \"\$(sums)\" = \"$before\" ] && vm control 'test ! -e /etc/ccomm/signals.xml.staged' && vm planner 'test ! -e /etc/ccomm/signals.xml.staged'"

# Back to the original everywhere, with deploy itself.
deploy "$W/orig.xml" >/dev/null 2>"$W/restore.err" || sed 's/^/  restore: /' "$W/restore.err"
vm control 'systemctl stop ccq-deploy-pub 2>/dev/null; true' >/dev/null
check "the original configuration back on both boards" \
	eval "vm control 'cmp -s /etc/ccomm/signals.xml /run/ccq/signals.xml.orig' && vm planner 'cmp -s /etc/ccomm/signals.xml /run/ccq/signals.xml.orig'"
finish
