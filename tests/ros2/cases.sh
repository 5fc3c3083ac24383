# SPDX-License-Identifier: Apache-2.0
# The cases of tests/ros2/run (sourced there, after the boards and the bridge are up).

# ---- ROS 2 conventions: topic names, DDS type names, USER_DATA typehash
check "DDS endpoints: rt/ccomm/<signal>, std_msgs::msg::dds_::*_ types, typehash=RIHS01 user data" \
  peer discover rt/ccomm/pos=Float64 rt/ccomm/joints=Float64MultiArray rt/ccomm/counts=Int32MultiArray \
  rt/ccomm/ticks=UInt32 rt/ccomm/big=Int64 rt/ccomm/gain=Float32MultiArray rt/ccomm/ready=Bool \
  rt/ccomm/alarm=Int64MultiArray rt/ccomm/setpoint=Float64MultiArray:sub rt/ccomm/enable=Bool:sub \
  rt/ccomm/cmd=Int32:sub

# ---- board A -> ROS 2: every value, right type, value and source timestamp
a_to_ros() {  # a_to_ros SIGNAL ROS_TYPE CCOMM_TYPE COUNT N [--event]
  local sig=$1 rtype=$2 ctype=$3 count=$4 n=$5; shift 5
  echo_start "$sig" "$sig" "$rtype" --count "$n" --timeout 20 "$@" || return 1
  app pub "$sig" "$n" 50 >"$WORK/$sig.app" || return 1  # 50 Hz: values, not throughput
  wait "$ECHO_PID" || { cat "$WORK/$sig.result"; return 1; }
  checks samples "$WORK/$sig.jsonl" --n "$n" --type "$ctype" --count "$count" \
    --mono-minus-wall "$(mono_minus_wall "$sig")"
}
check "A -> ROS 2: double scalar (Float64), value and source timestamp = ccomm write time" a_to_ros pos Float64 double 1 20

# ---- the source timestamp is the value's production time on the common time base
# Values stamped as produced 300 ms before board A's app hands them to ccomm (a sensor's
# sample time): a bridge stamping its own write time or the arrival is 300 ms late.
produced_ago() {  # produced_ago SIGNAL N AGO_MS [checks samples args]: A writes N, B's reader checks stamps
  local sig=$1 n=$2 ago=$3; shift 3
  echo_start "$sig-ago" "$sig" Float64 --count "$n" --timeout 20 || return 1
  app pub "$sig" "$n" 50 "$ago" >"$WORK/$sig-ago.app" || return 1
  wait "$ECHO_PID" || { cat "$WORK/$sig-ago.result"; return 1; }
  checks samples "$WORK/$sig-ago.jsonl" --n "$n" --type double --count 1 \
    --mono-minus-wall "$(mono_minus_wall "$sig-ago")" "$@"
}
grew_by() {  # grew_by BEFORE AFTER N: two counters read from the bridge, AFTER = BEFORE + N
  [[ $1 =~ ^[0-9]+$ && $2 =~ ^[0-9]+$ ]] && (( $2 - $1 == $3 ))
}
p0=$(bridge_stat pos stamped_production); l0=$(bridge_stat pos stamped_local)
check "A -> ROS 2: values produced 300 ms before A's app wrote them carry their production time (+/- 2 ms), on B's wall clock although A's monotonic clock is $(( MONO_SHIFT_NS / 1000000000 )) s ahead" \
  produced_ago pos 20 300
p1=$(bridge_stat pos stamped_production); l1=$(bridge_stat pos stamped_local)
check "  ... all 20 stamped from production ($p0 -> $p1), none locally ($l0 -> $l1)" \
  bash -c "$(declare -f grew_by); grew_by '$p0' '$p1' 20 && grew_by '$l0' '$l1' 0"
# B's clock not synced (its ptp4l killed: lost): the production time is unknown; the stamp
# is the arrival (300 ms after the production), counted, and the bridge says so.
if [[ -n ${PTP_PID[planner]:-} ]]; then
  kill -9 "${PTP_PID[planner]}"; wait "${PTP_PID[planner]}" 2>/dev/null
  b_clock_lost() { [[ $(clock_of planner planner) = lost ]]; }  # in the view the bridge asks
  check "B's ptp4l killed: B's clock lost" wait_for 30 b_clock_lost
  check "  ... then values carry their arrival on B as source timestamp (300 ms after production, +/- 100 ms)" \
    produced_ago pos 20 300 --stamp-offset-ms 300 --stamp-tolerance-ms 100
  l2=$(bridge_stat pos stamped_local)
  check "  ... each counted as stamped_local ($l1 -> $l2) and the bridge's log says that stamps are local" \
    bash -c "$(declare -f grew_by); grew_by '$l1' '$l2' 20 && grep -q 'pos: source timestamps are local, the arrival here: production time unknown (local_unsynced)' '$BRIDGE_LOG'"
  start_ptp4l planner UDPv4
  check "  ... B's ptp4l restarted: both clocks synced again" wait_for 60 both_synced
fi
check "A -> ROS 2: int32[3] (Int32MultiArray)" a_to_ros counts Int32MultiArray int32 3 20
check "A -> ROS 2: uint32 (UInt32)" a_to_ros ticks UInt32 uint32 1 20
check "A -> ROS 2: int64 (Int64)" a_to_ros big Int64 int64 1 20
check "A -> ROS 2: float[2] (Float32MultiArray)" a_to_ros gain Float32MultiArray float 2 20
check "A -> ROS 2: bool (Bool)" a_to_ros ready Bool bool 1 20
# The test participant types UInt8MultiArray's data as sequence<uint8> (XTypes TK_UINT8,
# what ROS 2's IDL says), the bridge as sequence<octet>: with type information on its
# endpoints, the bridge's Cyclone DDS 0.10.2 looked the peer's type up and crashed on it
# (SIGSEGV in the type-lookup thread, upstream #1554).
check "A -> ROS 2: bool[3] (UInt8MultiArray) to a peer whose type says sequence<uint8>" a_to_ros flags UInt8MultiArray bool 3 20
check "  ... and the bridge is still running after that peer came and went" kill -0 "$BRIDGE_PID"
check "A -> ROS 2: event int64[2], 200 in a burst, each once and in order (reliable keep-all)" \
  a_to_ros alarm Int64MultiArray int64 2 200 --event

# ---- ROS 2 -> board A: values land fresh, with their own seq
ros_to_a() {  # ros_to_a SIGNAL ROS_TYPE VALUES_JSON EXPECT_JSON N [pub args]
  local sig=$1 rtype=$2 values=$3 expect=$4 n=$5; shift 5
  app watch "$sig" "$n" 15 >"$WORK/$sig.watch" 2>&1 &
  local w=$!
  sleep 0.3
  peer pub "rt/ccomm/$sig" "$rtype" "$values" "$@" >"$WORK/$sig.pub" || { cat "$WORK/$sig.pub"; return 1; }
  wait "$w" || { note "watch: $(tail -3 "$WORK/$sig.watch")"; return 1; }
  checks watch "$WORK/$sig.watch" --expect "$expect"
}
check "ROS 2 -> A: Float64MultiArray into double[3], fresh on board A" \
  ros_to_a setpoint Float64MultiArray '[[1.5,2.5,3.5],[4,5,6],[7,8,9]]' '[[1.5,2.5,3.5],[4,5,6],[7,8,9]]' 3 --interval 0.05
check "ROS 2 -> A: Bool into bool" ros_to_a enable Bool '[true]' '[1]' 1
events=$("$CCOMM_PYTHON" -c 'print(list(range(1, 51)))')
check "ROS 2 -> A: 50 Int32 events, each once and in order" ros_to_a cmd Int32 "$events" "$events" 50 --event

# ---- bad input from DDS: refused, counted, nothing (half-)written
before=$(bridge_stat setpoint refused_length)
app watch setpoint 1 3 >"$WORK/bad.watch" 2>&1 &
w=$!
peer pub rt/ccomm/setpoint Float64MultiArray '[[1,2],[1,2,3,4],{"data":[1,2,3],"count":4}]' >/dev/null
wait "$w"; rc=$?
after=$(bridge_stat setpoint refused_length)
check "DDS samples of the wrong length (2, 4) or layout are refused and counted ($before -> $after)" \
  bash -c "[[ $((after - before)) -eq 3 ]]"
check "  ... and nothing reached board A" bash -c "[[ $rc -ne 0 ]] && ! grep -q '^[0-9]' '$WORK/bad.watch'"
# A layout is checked in every dimension: 3x2 (or strides that do not fit) with 3 values is
# refused; 3x1 with 3 values is a correct layout of the same data and is written.
before=$(bridge_stat setpoint refused_length); w_before=$(bridge_stat setpoint written)
peer pub rt/ccomm/setpoint Float64MultiArray \
  '[{"data":[1,2,3],"dims":[[3,6],[2,2]]},{"data":[1,2,3],"dims":[[3,3],[1,2]]},{"data":[7,8,9],"dims":[[3,3],[1,1]]}]' \
  --interval 0.05 >/dev/null
after=$(bridge_stat setpoint refused_length); w_after=$(bridge_stat setpoint written)
check "a multi-dimensional layout is checked in every dimension (3x2 over 3 values refused: $before -> $after; 3x1 written: $w_before -> $w_after)" \
  bash -c "[[ $((after - before)) -eq 2 && $((w_after - w_before)) -eq 1 ]]"
peer pub rt/ccomm/setpoint Int32MultiArray '[[1,2,3]]' --match-timeout 3 >/dev/null 2>&1
wrong=$(bridge_stat setpoint wrong_type_peers)
check "a DDS writer of another type (Int32MultiArray) on the topic is refused and counted ($wrong)" \
  bash -c "[[ $wrong -ge 1 ]]"

# ---- 1 kHz for 10 s, 36 doubles: zero loss, counted by the app, the bridge and the reader
signal_stat() {  # signal_stat NODE SIGNAL FIELD: ccommd's per-signal counter
  stats "$1"
  "$CCOMM_PYTHON" -c 'import json,sys; d=json.load(open(sys.argv[1]))
print([s for s in d["signals"] if s["name"] == sys.argv[2]][0][sys.argv[3]])' "$WORK/stats-$1.json" "$2" "$3"
}
# One run; sets KHZ_LOSS (values the reader missed) and KHZ_DDS_LOSS (published, not received).
khz_run() {
  local pub0 skip0 rx0 lost0 pub1 skip1 rx1 lost1 got
  pub0=$(bridge_stat joints published); skip0=$(bridge_stat joints skipped)
  rx0=$(signal_stat planner joints rx); lost0=$(signal_stat planner joints lost)
  KHZ_LOSS=10000 KHZ_DDS_LOSS=-1 KHZ_REF_LOSS=0
  echo_start joints joints Float64MultiArray --count 10000 --timeout 16 --event || return 1
  # The reference: a plain ccomm app on B reading the same signal, at the bridge's priority.
  fifo 50 ip netns exec "$NS_P" env CCOMM_NODE=planner "$WORK/board_app" watch joints 10000 16 >"$WORK/joints.ref" &
  local ref=$!
  sleep 0.2
  fifo 55 ip netns exec "$NS_C" env CCOMM_NODE=control "$WORK/board_app" pub joints 10000 1000 >"$WORK/joints.app"
  wait "$ECHO_PID"
  wait "$ref"
  pub1=$(bridge_stat joints published); skip1=$(bridge_stat joints skipped)
  rx1=$(signal_stat planner joints rx); lost1=$(signal_stat planner joints lost)
  got=$(json_get "$WORK/joints.result" received)
  local ref_got
  ref_got=$(grep -c '^[0-9]' "$WORK/joints.ref")
  KHZ_LOSS=$((10000 - got)) KHZ_DDS_LOSS=$((pub1 - pub0 - got)) KHZ_REF_LOSS=$((10000 - ref_got))
  figure "1 kHz x 10 s x 36 doubles, try $1: app $(cat "$WORK/joints.app"), ccommd B received $((rx1 - rx0)) lost $((lost1 - lost0)), a ccomm app on B read $ref_got, bridge published $((pub1 - pub0)) skipped $((skip1 - skip0)), ROS 2 reader received $got"
}
# A state signal is last-value-wins: a reader loses a value when two arrive closer than
# it can read them (a stall upstream delivers frames in a burst) or when it is not
# scheduled within the period. On a shared, loaded 2-core VM that happens now and then
# even at SCHED_FIFO, so the run is tried up to 3 times and passes on the first that loses
# nothing; every try's counts are printed. A plain ccomm app on B reads the same signal
# as the reference: if it also lost values in every try, this machine cannot carry
# 1 kHz right now and the zero-loss check is reported as skipped with the counts; the
# bridge must still never lose more than that app, and the DDS leg nothing, in any try.
dds_loss=0 ref_lost_every_try=1 bridge_worse=0 dds_losses=""
for try in 1 2 3; do
  khz_run "$try"
  dds_losses+="${dds_losses:+, }$KHZ_DDS_LOSS"
  [[ $KHZ_DDS_LOSS -ne 0 ]] && dds_loss=1
  [[ $KHZ_REF_LOSS -eq 0 ]] && ref_lost_every_try=0
  [[ $KHZ_LOSS -gt $KHZ_REF_LOSS ]] && bridge_worse=$((bridge_worse + 1))
  [[ $KHZ_LOSS -eq 0 ]] && break
done
what="1 kHz x 10 s x 36 doubles: zero loss end to end (app 10000 = bridge published = ROS 2 reader)"
if [[ $KHZ_LOSS -ne 0 && $ref_lost_every_try -eq 1 ]]; then
  ok "$what # SKIP a plain ccomm app on B lost values too in all 3 tries (load $(cut -d' ' -f1 /proc/loadavg)): not a real-time host now"
  check "  ... the bridge lost no more than that app in at least one try ($bridge_worse of 3 worse)" \
    bash -c "[[ $bridge_worse -lt 3 ]]"
else
  check "$what, try $try" bash -c "[[ $KHZ_LOSS -eq 0 ]] && grep -q 'written 10000' '$WORK/joints.app'"
  check "  ... every value once, in order, right values and source timestamps" \
    checks samples "$WORK/joints.jsonl" --n 10000 --type double --count 36 --mono-minus-wall "$(mono_minus_wall joints)"
fi
check "  ... in every try, every sample the bridge published reached the ROS 2 reader (published - received: $dds_losses)" bash -c "[[ $dds_loss -eq 0 ]]"

# ---- stale: cut the board link; the ROS 2 reader's deadline (50 ms) fires in time
stale0=$(bridge_stat pos stale)
if echo_start stale pos Float64 --count 1000000 --timeout 3 --deadline-ms 50; then
  app pub pos 400 100 >/dev/null &   # 100 Hz: period 10 ms
  a=$!
  sleep 1.5
  ip -n "$NS_C" link set eth0 down
  cut=$(date +%s%N)  # after: the link is down from here on, whatever ip's own run time
  wait "$ECHO_PID"
  wait "$a"
  ip -n "$NS_C" link set eth0 up
  "$CCOMM_PYTHON" - "$WORK/stale.result" "$WORK/stale.jsonl" "$cut" >"$WORK/stale.check" <<'PY'
import json, sys
res = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
rows = [json.loads(l) for l in open(sys.argv[2])]
cut = int(sys.argv[3])
misses = [t for t in res["deadline_misses"] if t > cut]
told = (misses[0] - cut) / 1e6 if misses else None
# nothing stale re-published: no sample arrives after the reader was told
after = [r for r in rows if misses and r["rx"] > misses[0]]
print("told_ms", told, "samples_after_told", len(after), "samples", len(rows))
sys.exit(0 if told is not None and told <= 50 + 10 + 5 and not after and rows else 1)
PY
  rc=$?
  figure "stale: link cut -> ROS 2 deadline missed after $(cat "$WORK/stale.check") (limit 50 ms stale_after + 10 ms period, +5 ms scheduling)"
  check "stale: the ROS 2 side is told within stale_after_ms + 1 period of the cut, nothing stale re-published" \
    bash -c "[[ $rc -eq 0 ]]"
  stale1=$(bridge_stat pos stale)
  check "  ... and the bridge counted pos going stale ($stale0 -> $stale1)" bash -c "[[ $stale1 -gt $stale0 ]]"
else
  not_ok "stale: reader matched"
fi

# ---- the bridge survives ccommd restarts (same configuration; a new one retires the segment)
flows() { a_to_ros pos Float64 double 1 5 >/dev/null && ros_to_a enable Bool '[false]' '[0]' 1 >/dev/null; }
stop_daemon planner
start_rt_daemon planner
sleep 0.3
check "after a ccommd restart on B (same configuration) values flow both ways" flows
production_again() {  # the restarted ccommd has a new system view: the bridge follows it
  wait_for 60 both_synced || { note "clocks not synced again"; return 1; }
  local p0; p0=$(bridge_stat pos stamped_production)
  produced_ago pos 20 300 && grew_by "$p0" "$(bridge_stat pos stamped_production)" 20
}
check "  ... and once B's clock is synced again, source timestamps are production times again (the bridge opened the new ccommd's view)" \
  production_again
# The new configuration also changes pos's stale_after_ms (50 -> 120 ms): the bridge must
# offer the new deadline after it reattaches.
sed -e 's|</ccomm>|  <signal name="extra" type="double" producer="control" consumers="planner"/>\n</ccomm>|' \
    -e 's|<signal name="pos" type="double" producer="control" consumers="planner" stale_after_ms="50"/>|<signal name="pos" type="double" producer="control" consumers="planner" stale_after_ms="120"/>|' \
  "$HERE/ros2.xml" >"$WORK/ros2-changed.xml"
check "the bridge offers pos's deadline of the configuration (50 ms)" peer deadline rt/ccomm/pos 50
stop_daemon control
stop_daemon planner
start_rt_daemon control "$WORK/ros2-changed.xml"
start_rt_daemon planner "$WORK/ros2-changed.xml"
sleep 0.5
check "after ccommd restarts with a new configuration the bridge reopens and values flow" flows
check "  ... and after stale_after_ms changed to 120 ms in the new configuration, offers 120 ms" \
  peer deadline rt/ccomm/pos 120
reopens=$(bridge_stat - reopens)
check "  ... the bridge counted its reopens ($reopens)" bash -c "[[ $reopens -ge 1 ]]"
# A second bridge for the same node and domain would publish every value twice: refused.
timeout 20 ip netns exec "$NS_P" env CCOMM_NODE=planner "$BIN/ccomm-ros2" --config "$HERE/ros2.xml" \
  >"$WORK/second.out" 2>&1; rc=$?
check "a second bridge on the same node and DDS domain is refused (exit 2, naming the first's pid) (exit $rc)" \
  bash -c "[[ $rc -eq 2 ]] && grep -q 'another ccomm-ros2 (pid $BRIDGE_PID) already bridges node planner on DDS domain 42' '$WORK/second.out'"
check "the bridge is still running after every DDS peer of this suite came and went" kill -0 "$BRIDGE_PID"
errs=$(bridge_stat joints dds_errors)
check "  ... without a DDS error ($errs)" bash -c "[[ $errs -eq 0 ]]"

# ---- fuzzed DDS samples: every sample is written whole or refused whole, and counted
fuzz_values=$("$CCOMM_PYTHON" -c '
import json, random
random.seed(2026)
out = []
for _ in range(200):
    n = random.choice([0, 1, 2, 3, 3, 3, 4, 7, 64])
    data = [random.uniform(-1e6, 1e6) for _ in range(n)]
    count = random.choice([n, n, n, 3, 0, 5, 2**32 - 1])
    out.append({"data": data, "count": count})
print(json.dumps(out))')
valid=$("$CCOMM_PYTHON" -c 'import json,sys; v=json.loads(sys.argv[1]); print(sum(1 for s in v if len(s["data"]) == 3 and s["count"] == 3))' "$fuzz_values")
r0=$(bridge_stat setpoint received); w0=$(bridge_stat setpoint written); f0=$(bridge_stat setpoint refused_length)
peer pub rt/ccomm/setpoint Float64MultiArray "$fuzz_values" --interval 0.003 >/dev/null
r1=$(bridge_stat setpoint received); w1=$(bridge_stat setpoint written); f1=$(bridge_stat setpoint refused_length)
figure "fuzzed samples: 200 sent ($valid well-formed), bridge received $((r1 - r0)), wrote $((w1 - w0)), refused $((f1 - f0))"
check "fuzzed Float64MultiArray samples (random lengths and layouts): each written whole or refused and counted" \
  bash -c "[[ $((r1 - r0)) -eq $((w1 - w0 + f1 - f0)) && $((w1 - w0)) -le $valid && $((f1 - f0)) -le $((200 - valid)) && $((r1 - r0)) -ge 190 ]]"
check "  ... with no sample lost on this loopback: exactly the $valid well-formed ones written" \
  bash -c "[[ $((r1 - r0)) -ne 200 || $((w1 - w0)) -eq $valid ]]"
PATH=$BIN:$PATH "$BIN/ccomm" ros2 --help >"$WORK/cli-help" 2>&1
check "'ccomm ros2' runs the bridge (ccomm-ros2 on PATH)" grep -q 'rt/NAMESPACE/SIGNAL' "$WORK/cli-help"
kill -TERM "$BRIDGE_PID"; wait "$BRIDGE_PID"; rc=$?
check "the bridge exits 0 on SIGTERM, printing its counters" bash -c "[[ $rc -eq 0 ]] && tail -1 '$BRIDGE_LOG' | grep -q '\"reopens\"'"
