#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# 20-sim integration test against a real ccommd:
#   - the C-code target: the example controller generated from its tokens file, run as a
#     periodic task, checked as a closed loop by pd_check (also with --param kp=4),
#     plus start-up failures for unmapped ports and unknown parameters;
#   - the step order: a model with a derivative kick, states and a matrix, generated for
#     Discrete, Euler, RungeKutta2 and RungeKutta4, sample by sample against a reference
#     of 20-sim's documented order (test/step_order.py); the template language;
#   - the documented function list against what the target defines (test/doc_functions.py);
#   - the 4C component: generated from signals.xml, run by the 4C harness, same checks.
# Usage: test.sh CCOMM_BIN_DIR [INTEGRATION_BIN_DIR]  (ccommd/ccomm, then the built tests)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=$(cd "${1:?usage: test.sh CCOMM_BIN_DIR [INTEGRATION_BIN_DIR]}" && pwd)
ibin=$(cd "${2:-$1}" && pwd)
source "$here/../lib.sh"
cfg=$here/example/signals.xml
out=$(mktemp -d)
trap 'it_cleanup; rm -rf "$out"' EXIT
fail=0

it_start_ccommd "$bin" "$cfg" ctrl

echo "== 20-sim C-code target: generated PDController task"
it_bg "$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 20 --stats-interval 0 >"$out/task.out" 2>"$out/task.err"
task=$IT_PID
sleep 0.2
if command -v chrt >/dev/null; then echo "task scheduling: $(chrt -p "$task" 2>&1 | head -1)"; fi
"$ibin/ccomm_20sim_pd_check" ctrl || fail=1
it_stop "$task"
cat "$out/task.out"
if [ "$IT_RC" != 0 ]; then echo "FAIL task exit status $IT_RC"; cat "$out/task.err"; fail=1; fi
grep -q "cycles=[1-9]" "$out/task.out" || { echo "FAIL task printed no cycle count"; fail=1; }

echo "== 20-sim C-code target: --param kp=4"
it_bg "$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 20 --param kp=4 >"$out/task2.out" 2>"$out/task2.err"
task=$IT_PID
"$ibin/ccomm_20sim_pd_check" ctrl 4 || fail=1
it_stop "$task"
[ "$IT_RC" = 0 ] || { echo "FAIL task exit status $IT_RC"; fail=1; }

echo "== 20-sim C-code target: start-up errors"
rc=0
"$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 0 --duration 1 --map position=no_such_signal >/dev/null 2>"$out/e1" || rc=$?
if [ "$rc" = 1 ] && grep -q "input port 'position': no signal 'no_such_signal'" "$out/e1"; then
  echo "PASS unmapped port refused: $(head -1 "$out/e1")"
else echo "FAIL unmapped port: exit $rc: $(cat "$out/e1")"; fail=1; fi
rc=0
"$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 0 --duration 1 --param nosuch=1 >/dev/null 2>"$out/e2" || rc=$?
if [ "$rc" = 1 ] && grep -q "no parameter 'nosuch'; the model has: kp kd reference" "$out/e2"; then
  echo "PASS unknown parameter refused"
else echo "FAIL unknown parameter: exit $rc: $(cat "$out/e2")"; fail=1; fi
rc=0
# Output error_integral onto signal position, which input port position reads.
"$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 0 --duration 1 --map error_integral=position >/dev/null 2>"$out/e3" || rc=$?
if [ "$rc" = 1 ] && grep -q "connected to both an input and an output" "$out/e3"; then
  echo "PASS signal used as input and output refused"
else echo "FAIL input/output clash: exit $rc: $(cat "$out/e3")"; fail=1; fi

echo "== 20-sim C-code target: a period other than the model's step size"
rc=0
# PDController's step size is 2 ms: at 4 ms one second of real time would be half a second of model time.
"$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 0 --duration 0.2 --period 0.004 >/dev/null 2>"$out/p1" || rc=$?
if [ "$rc" = 1 ] && grep -q "differs from the model's step size 0.002 s" "$out/p1" && grep -q "0.5 x real time" "$out/p1"; then
  echo "PASS period mismatch refused: $(head -1 "$out/p1")"
else echo "FAIL period mismatch: exit $rc: $(cat "$out/p1")"; fail=1; fi
rc=0
"$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 0 --duration 0.2 --period 0.004 --allow-time-scaling \
  >/dev/null 2>"$out/p2" || rc=$?
if [ "$rc" = 0 ] && grep -q "model time runs at 0.5 x real time" "$out/p2"; then
  echo "PASS --allow-time-scaling runs and says so"
else echo "FAIL --allow-time-scaling: exit $rc: $(cat "$out/p2")"; fail=1; fi
rc=0
"$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 0 --duration 0.2 --period 2ms >/dev/null 2>"$out/p3" || rc=$?
if [ "$rc" = 1 ] && grep -q "wants a number of seconds, got '2ms'" "$out/p3"; then
  echo "PASS --period 2ms refused"
else echo "FAIL --period 2ms: exit $rc: $(cat "$out/p3")"; fail=1; fi

echo "== 20-sim C-code target: vector ports and an event input (VectorGain)"
it_bg "$ibin/ccomm_20sim_vectorgain" --node ctrl --priority 20 >"$out/vg.out" 2>"$out/vg.err"
vg=$IT_PID
expect() {  # expect SIGNAL PATTERN WHAT: polls `ccomm echo --once` for up to 2 s
  local got="" i
  for i in $(seq 40); do
    got=$("$bin/ccomm" --node ctrl echo "$1" --once 2>&1) || true
    if grep -qE "$2" <<<"$got"; then echo "PASS $3: $got"; return 0; fi
    sleep 0.05
  done
  echo "FAIL $3: $got (want $2)"
  fail=1
}
"$bin/ccomm" --node ctrl pub vin 1.3 2 -3.2
expect vout '^vout \[3, 4, -6\] fresh' "vin[1..3] -> vout[1..3] = 2*vin, rounded to int32"
"$bin/ccomm" --node ctrl pub vin 1e12 0 0
expect vout '^vout \[2147483647, 0, 0\] fresh' "int32 output saturates"
"$bin/ccomm" --node ctrl pub cmd 5
expect last_cmd '^last_cmd 5 fresh' "event input reaches the model"
sleep 0.2
expect last_cmd '^last_cmd 5 fresh' "event input holds between events"
"$bin/ccomm" --node ctrl pub cmd 7
"$bin/ccomm" --node ctrl pub cmd 9
expect last_cmd '^last_cmd 9 fresh' "newest of two events"
it_stop "$vg"
[ "$IT_RC" = 0 ] || { echo "FAIL VectorGain exit status $IT_RC: $(cat "$out/vg.err")"; fail=1; }

echo "== 20-sim C-code target: code generation for every integration method"
for m in Discrete Euler RungeKutta2 RungeKutta4; do
  sed "s/\[CDATA\[Euler\]\]/[CDATA[$m]]/" "$here/example/PDController_tokens.xml" >"$out/t_$m.xml"
  "$CCOMM_PYTHON" "$here/tokensubst.py" --targets "$here/ccode-target/Targets.ini" --target ccomm \
    --tokens "$out/t_$m.xml" --out "$out/gen_$m" >/dev/null
  if ${CC:-cc} -std=c11 -Wall -Wextra -Wshadow -Werror -c -I"$here/../../src/include" \
      -o "$out/$m.o" "$out/gen_$m/xxinteg.c"; then echo "PASS $m compiles"; else echo "FAIL $m"; fail=1; fi
done
if "$CCOMM_PYTHON" "$here/tokensubst.py" --targets "$here/ccode-target/Targets.ini" --target ccomm \
    --tokens <(sed 's/\[CDATA\[Euler\]\]/[CDATA[BDF]]/' "$here/example/PDController_tokens.xml") \
    --out "$out/gen_bdf" 2>"$out/e4"; then echo "FAIL unsupported method accepted"; fail=1;
else echo "PASS unsupported method refused: $(cat "$out/e4")"; fi

echo "== 20-sim C-code target: step order and integration methods against 20-sim's documented order"
# StepOrder: derivative kick, two states, a gain matrix; sample by sample, all four methods.
if "$CCOMM_PYTHON" "$here/test/step_order.py" --work "$out/step_order" --cc "${CC:-cc}" \
     --ccomm-include "$here/../../src/include" --ccomm-lib "$(cd "$bin/../lib" && pwd)"; then :; else fail=1; fi

echo "== 20-sim C-code target: the matrix model (StepOrder, Euler) as a task against ccommd"
# u = K w with K = [1 0.5; -0.25 2], w = [w1; y[2]]: whatever w1 is at that sample,
# u[2] = -0.25 (u[1] - 0.5 y[2]) + 2 y[2] must hold for every output the task writes.
it_bg "$ibin/ccomm_20sim_steporder" --node ctrl --priority 0 >"$out/so.out" 2>"$out/so.err"
so=$IT_PID
it_bg "$bin/ccomm" --node ctrl pub r 1 --rate 200 --count 200
it_bg "$bin/ccomm" --node ctrl pub y 0.2 0.5 --rate 200 --count 200
so_ok=0
for i in $(seq 40); do
  sleep 0.05
  got_u=$("$bin/ccomm" --node ctrl echo u --once 2>&1) || true
  got_i=$("$bin/ccomm" --node ctrl echo integral --once 2>&1) || true
  if "$CCOMM_PYTHON" - "$got_u" "$got_i" <<'PY'
import re, sys
u = re.match(r"u \[([^,\]]+), ([^\]]+)\] fresh", sys.argv[1])
i = re.match(r"integral (\S+) fresh", sys.argv[2])
ok = bool(u and i) and float(i.group(1)) > 0.0
if ok:
    u1, u2 = float(u.group(1)), float(u.group(2))
    ok = abs(u2 - (-0.25 * (u1 - 0.5 * 0.5) + 2.0 * 0.5)) <= 1e-4 * max(1.0, abs(u2))
sys.exit(0 if ok else 1)
PY
  then so_ok=1; break; fi
done
if [ "$so_ok" = 1 ]; then echo "PASS matrix model task: $got_u; $got_i"
else echo "FAIL matrix model task: u: $got_u; integral: $got_i"; cat "$out/so.err"; fail=1; fi
it_stop "$so"
[ "$IT_RC" = 0 ] || { echo "FAIL StepOrder task exit status $IT_RC: $(cat "$out/so.err")"; fail=1; }

echo "== 20-sim C-code target: matrix helpers (xxmatrix.c as generated)"
if ${CC:-cc} -std=c11 -Wall -Wextra -Wshadow -Werror -I"$out/step_order/gen_Euler" -o "$out/matrix_check" \
     "$here/test/matrix_check.c" "$out/step_order/gen_Euler/xxmatrix.c" -lm && "$out/matrix_check"; then :;
else echo "FAIL matrix helpers"; fail=1; fi

echo "== 20-sim C-code target: template language (%IF% with EQ/NEQ/NOT/AND/OR, undefined tokens)"
if "$CCOMM_PYTHON" "$here/test/tokensubst_check.py"; then :; else fail=1; fi

echo "== 20-sim C-code target: the documented function list against xxfuncs.c / xxmatrix.c"
if "$CCOMM_PYTHON" "$here/test/doc_functions.py" --cc "${CC:-cc}"; then :; else fail=1; fi

echo "== 20-sim C-code target: the generated project builds with its own CMakeLists.txt"
"$CCOMM_PYTHON" "$here/tokensubst.py" --targets "$here/ccode-target/Targets.ini" --target ccomm \
  --tokens "$here/example/PDController_tokens.xml" --out "$out/user" >/dev/null
if cmake -S "$out/user" -B "$out/user/build" -DCCOMM_INCLUDE_DIR="$here/../../src/include" \
     -DCCOMM_LIBRARY="$(cd "$bin/../lib" && pwd)/libccomm.so" >/dev/null &&
   cmake --build "$out/user/build" >/dev/null && "$out/user/build/PDController_ccomm" --help | grep -q "Inputs: 3, outputs: 2"; then
  echo "PASS generated project builds and runs (--help)"
else echo "FAIL generated project build"; fail=1; fi

echo "== 20-sim 4C component: generated driver in the 4C harness"
it_bg "$ibin/ccomm_20sim_4c_harness" >"$out/4c.out" 2>"$out/4c.err"
h=$IT_PID
"$ibin/ccomm_20sim_pd_check" ctrl || fail=1
it_stop "$h"
cat "$out/4c.out"
[ "$IT_RC" = 0 ] || { echo "FAIL 4C harness exit status $IT_RC: $(cat "$out/4c.err")"; fail=1; }

echo "== 20-sim 4C component: generator checks"
export CCOMM_CCOMMD=$bin/ccommd  # the generator reads signals.xml through ccommd --check --json
bad=$out/bad-signals.xml
sed 's/type="double"/type="doubel"/' "$cfg" >"$bad"
if "$CCOMM_PYTHON" "$here/4c/gen_4c.py" "$bad" ctrl "$out/gb" 2>"$out/e6"; then echo "FAIL bad type accepted"; fail=1;
elif grep -q "bad-signals.xml:[0-9]*: error" "$out/e6"; then echo "PASS ccommd's error for a bad file: $(head -1 "$out/e6")"
else echo "FAIL bad file: no FILE:LINE error: $(cat "$out/e6")"; fail=1; fi
if "$CCOMM_PYTHON" "$here/4c/gen_4c.py" "$cfg" nosuch "$out/g" 2>"$out/e5"; then echo "FAIL unknown node accepted"; fail=1;
else echo "PASS unknown node refused: $(cat "$out/e5")"; fi
if CCOMM_NODE=ctrl CCOMM_GEN_20SIM4C="$here/4c/gen_4c.py" "$bin/ccomm" gen 20sim4c "$cfg" "$out/gcli" >/dev/null &&
   grep -q '#define CCOMM4C_NODE "ctrl"' "$out/gcli/ccomm_4c.h"; then
  echo "PASS ccomm gen 20sim4c runs the generator"
else echo "FAIL ccomm gen 20sim4c"; fail=1; fi

echo "== 20-sim C-code target: started while ccommd is down"
# A clean stop leaves the segment for the next ccommd to adopt; a task must not take it
# for a running system and run on safe values in silence.
it_stop "${_it_pids[0]}"
rc=0
"$ibin/ccomm_20sim_pdcontroller" --node ctrl --priority 0 --duration 1 --wait-ccommd 0.5 >"$out/d1.out" 2>"$out/d1" || rc=$?
if [ "$rc" = 1 ] && grep -q "no ccommd is running for node ctrl (its segment exists but its heartbeat has stopped" "$out/d1" &&
   ! grep -q "cycles=" "$out/d1.out"; then
  echo "PASS task refused without a running ccommd: $(head -1 "$out/d1")"
else echo "FAIL task without ccommd: exit $rc: $(cat "$out/d1" "$out/d1.out")"; fail=1; fi

if [ "$fail" = 0 ]; then echo "20-sim integration: all checks passed"; else echo "20-sim integration: FAILED"; fi
exit "$fail"
