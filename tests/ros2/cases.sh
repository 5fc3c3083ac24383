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
  app pub "$sig" "$n" 200 >"$WORK/$sig.app" || return 1
  wait "$ECHO_PID" || { cat "$WORK/$sig.result"; return 1; }
  checks samples "$WORK/$sig.jsonl" --n "$n" --type "$ctype" --count "$count" \
    --mono-minus-wall "$(mono_minus_wall "$sig")"
}
check "A -> ROS 2: double scalar (Float64), value and source timestamp = ccomm write time" a_to_ros pos Float64 double 1 20
check "A -> ROS 2: int32[3] (Int32MultiArray)" a_to_ros counts Int32MultiArray int32 3 20
check "A -> ROS 2: uint32 (UInt32)" a_to_ros ticks UInt32 uint32 1 20
check "A -> ROS 2: int64 (Int64)" a_to_ros big Int64 int64 1 20
check "A -> ROS 2: float[2] (Float32MultiArray)" a_to_ros gain Float32MultiArray float 2 20
check "A -> ROS 2: bool (Bool)" a_to_ros ready Bool bool 1 20
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
events=$(python3 -c 'print(list(range(1, 51)))')
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
peer pub rt/ccomm/setpoint Int32MultiArray '[[1,2,3]]' --match-timeout 3 >/dev/null 2>&1
wrong=$(bridge_stat setpoint wrong_type_peers)
check "a DDS writer of another type (Int32MultiArray) on the topic is refused and counted ($wrong)" \
  bash -c "[[ $wrong -ge 1 ]]"
