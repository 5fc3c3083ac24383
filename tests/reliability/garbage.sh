#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The shared segment as a trust boundary (docs/reliability.md, "Trust model"): a client
# of the ccomm group writes random bytes over control's live segment (tests/reliability/
# garbage.c, a plain mmap of /dev/shm), first over every byte of the signals' data, then
# over every byte of the segment (header, directory, counters), while writers and
# validating readers (torture.c: self-consistent arrays with a checksum) run on both
# boards, locally and across the link.
# Checks: both ccommd and every other client stay alive; no reader ever gets a damaged
# value (every value read is validated, fresh or stale); the damage is detected and
# counted (the signals' `corrupt` counters, the readers' refusals); the planner board's
# own signals keep flowing; after control's ccommd restarts, values flow end to end.
#   GARBAGE_SECONDS (default 2) per phase
source "$(dirname "$0")/lib.sh"
require_root
require_build
build_torture
build_tool garbage -lrt
SECONDS_EACH=${GARBAGE_SECONDS:-2}

declare -A CMD NODE_OF CPID
CMD[w_state]="write t_state --rate 2000";  NODE_OF[w_state]=control
CMD[w_event]="write t_event --rate 500";   NODE_OF[w_event]=control
CMD[c_state_local]="check t_state";        NODE_OF[c_state_local]=control
CMD[c_event_local]="check t_event";        NODE_OF[c_event_local]=control
CMD[c_state_remote]="check t_state";       NODE_OF[c_state_remote]=planner
CMD[c_event_remote]="check t_event";       NODE_OF[c_event_remote]=planner
CMD[w_local]="write t_local --rate 2000";  NODE_OF[w_local]=planner
CMD[c_local]="check t_local";              NODE_OF[c_local]=planner
CLIENTS=(w_state w_event c_state_local c_event_local c_state_remote c_event_remote w_local c_local)
start_client() {
  # shellcheck disable=SC2086  # the arguments are word-split on purpose
  spawn "$WORK/$1.log" "${NODE_OF[$1]}" "$WORK/torture" -n "${NODE_OF[$1]}" ${CMD[$1]}
  CPID[$1]=$!
}
alive_clients() {
  local c n=0
  for c in "${CLIENTS[@]}"; do kill -0 "${CPID[$c]}" 2>/dev/null && n=$((n + 1)); done
  echo $n
}
corrupt_sum() {  # the signals' corrupt counters at NODE
  stats_json "$1" | "$CCOMM_PYTHON" -c 'import json,sys; print(sum(s.get("corrupt", 0) for s in json.load(sys.stdin)["signals"]))'
}
seq_of() { cli "$1" echo "$2" --once | sed -n 's/.* seq=\([0-9]*\).*/\1/p'; }

make_pair
start_daemon control || { not_ok "ccommd control starts"; finish; }
start_daemon planner || { not_ok "ccommd planner starts"; finish; }
for c in "${CLIENTS[@]}"; do start_client "$c"; done
sleep 1
check "all ${#CLIENTS[@]} clients running before the garbage" [ "$(alive_clients)" -eq ${#CLIENTS[@]} ]
base=$(corrupt_sum control)

# Phase 1: every byte of the signals' data, then random runs, while everything runs.
in_ns control "$WORK/garbage" "${CCOMM_SHM_PREFIX}control" data "$SECONDS_EACH" 1 | tee "$WORK/garbage-data.json" |
  sed 's/^/# /'
sleep 0.5
detected=$(( $(corrupt_sum control) - base ))
figure "data garbage: $detected damaged copies detected and counted at control (corrupt counters)"
check "ccommd control alive after garbage over the data" daemon_alive control
check "ccommd planner alive" daemon_alive planner
check "every client alive after garbage over the data ($(alive_clients)/${#CLIENTS[@]})" \
  [ "$(alive_clients)" -eq ${#CLIENTS[@]} ]
check "the damage was detected and counted ($detected)" [ "$detected" -gt 0 ]

# Phase 2: every byte of the segment, header and directory included.
in_ns control "$WORK/garbage" "${CCOMM_SHM_PREFIX}control" all "$SECONDS_EACH" 2 | tee "$WORK/garbage-all.json" |
  sed 's/^/# /'
a=$(seq_of planner t_local)
sleep 0.5
wait_for 20 eval 'b=$(seq_of planner t_local); [ "${b:-0}" -gt "${a:-0}" ]' 
check "ccommd control alive after garbage over the whole segment" daemon_alive control
check "ccommd planner alive" daemon_alive planner
check "every client alive after garbage over the whole segment ($(alive_clients)/${#CLIENTS[@]})" \
  [ "$(alive_clients)" -eq ${#CLIENTS[@]} ]
check "the planner's own signals still flow (t_local seq $a -> $b)" [ "${b:-0}" -gt "${a:-0}" ]
check "a new client refuses the damaged segment with a clear error" \
  bash -c "! ip netns exec '$NS_C' '$BIN/ccomm' --node control list 2>&1 | tee '$WORK/list.err' | grep -q .; grep -q 'layout version\\|cannot attach' '$WORK/list.err'"

# Restart control's ccommd: it retires the damaged segment and makes a new one; the
# attached clients reopen and values flow end to end again.
stop_daemon control >/dev/null
start_daemon control || not_ok "ccommd control restarts after the garbage"
# The writer reopens within a few ms; a loaded machine may take seconds: wait (bounded)
# until the planner's copy of t_state moves past its value before the restart.
a=$(seq_of planner t_state)
seq_moved() { b=$(seq_of planner t_state); [ "${b:-0}" -gt "${a:-0}" ]; }
wait_for 30 seq_moved
check "values flow end to end after control's restart (t_state at planner: seq $a -> $b)" [ "${b:-0}" -gt "${a:-0}" ]
check "the writer reopened instead of giving up" bash -c "! grep -q 'ccomm_open' '$WORK/w_state.log'"

for c in "${CLIENTS[@]}"; do kill -INT "${CPID[$c]}" 2>/dev/null; done
for c in "${CLIENTS[@]}"; do wait "${CPID[$c]}" 2>/dev/null; done
bad=$(cat "$WORK"/c_*.log | grep -c '"corrupt":true')
refused=$(cat "$WORK"/c_*.log | sed -n 's/.*"final":true.*"detected":\([0-9]*\).*/\1/p' | paste -sd+ | bc)
figure "readers refused $refused damaged copies; $bad damaged values were returned to a reader"
check "no reader ever got a damaged value ($bad)" [ "$bad" -eq 0 ]
finish
