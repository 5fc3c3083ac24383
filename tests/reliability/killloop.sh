#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Crash safety: kill -9 at random points, in a loop, of any writer, any reader, either
# ccommd (sometimes right after it starts, while it creates or re-adopts its segment),
# and now and then restart control's ccommd with a different configuration (its segment
# is replaced: clients must notice and reopen). Every reader validates every value it
# sees (tests/reliability/torture.c: self-consistent int64 arrays with a checksum, per
# writer in order), locally and across the link, states and events.
# Checks: no reader ever saw a corrupt value; the daemons re-adopt their segments; no
# stale segment is left behind; afterwards values flow again end to end, local writes
# succeed, and clients that lost their segment reopened it.
#
#   KILL_ITERATIONS (default 40), KILL_SEED (default: random, printed)
source "$(dirname "$0")/lib.sh"
require_root
require_build
build_torture
ITER=${KILL_ITERATIONS:-40}
SEED=${KILL_SEED:-$RANDOM}
RANDOM=$SEED
note "seed $SEED (KILL_SEED=$SEED to repeat), $ITER iterations"

# A second configuration for control: one more local signal, so a different layout.
sed 's|</ccomm>|  <signal name="t_extra" type="int64" count="4" producer="control"/>\n</ccomm>|' "$CONFIG" \
  >"$WORK/other.xml"

declare -A CMD NODE_OF  # client name -> torture arguments, node
CMD[w_state1]="write t_state --rate 2000";  NODE_OF[w_state1]=control
CMD[w_state2]="write t_state --rate 2000";  NODE_OF[w_state2]=control
CMD[w_event]="write t_event --rate 500";    NODE_OF[w_event]=control
CMD[c_state_local]="check t_state";         NODE_OF[c_state_local]=control
CMD[c_event_local]="check t_event";         NODE_OF[c_event_local]=control
CMD[c_state_remote]="check t_state";        NODE_OF[c_state_remote]=planner
CMD[c_event_remote]="check t_event";        NODE_OF[c_event_remote]=planner
CMD[w_local]="write t_local --rate 5000";   NODE_OF[w_local]=planner
CMD[c_local]="check t_local";               NODE_OF[c_local]=planner
CLIENTS=(w_state1 w_state2 w_event c_state_local c_event_local c_state_remote c_event_remote w_local c_local)
declare -A CPID GEN
KILLED_BY_US=()
CORRUPT=0

start_client() {
  local c=$1
  GEN[$c]=$(( ${GEN[$c]:-0} + 1 ))
  # shellcheck disable=SC2086  # the arguments are word-split on purpose
  spawn "$WORK/$c.${GEN[$c]}.log" "${NODE_OF[$c]}" "$WORK/torture" -n "${NODE_OF[$c]}" ${CMD[$c]}
  CPID[$c]=$!
}
# A client that exited without being killed by us: a checker found a corrupt value,
# or something else went wrong. Either is a failure.
check_clients() {
  local c
  for c in "${CLIENTS[@]}"; do
    if ! kill -0 "${CPID[$c]}" 2>/dev/null; then
      wait "${CPID[$c]}"
      local rc=$?
      echo "# client $c exited by itself (status $rc): $(tail -n2 "$WORK/$c.${GEN[$c]}.log")"
      grep -q '"corrupt":true' "$WORK/$c.${GEN[$c]}.log" && CORRUPT=$((CORRUPT + 1))
      UNEXPECTED=$((UNEXPECTED + 1))
      start_client "$c"
    fi
  done
}
kill9() { kill -9 "$1" 2>/dev/null; wait "$1" 2>/dev/null; }

make_pair
start_daemon control || { not_ok "ccommd control starts"; finish; }
start_daemon planner || { not_ok "ccommd planner starts"; finish; }
for c in "${CLIENTS[@]}"; do start_client "$c"; done
sleep 1

UNEXPECTED=0
declare -A KILLS
ADOPT_EXPECTED=0
for i in $(seq "$ITER"); do
  sleep "0.$(printf '%03d' $((RANDOM % 300)))"
  check_clients
  r=$((RANDOM % 100))
  if (( r < 30 )); then  # a daemon, at a random point of its life
    node=$([[ $((RANDOM % 2)) = 0 ]] && echo control || echo planner)
    kill9 "${DPID[$node]}"
    KILLS[ccommd-$node]=$(( ${KILLS[ccommd-$node]:-0} + 1 ))
    sleep "0.$(printf '%03d' $((RANDOM % 200)))"
    start_daemon "$node" || not_ok "iteration $i: ccommd $node restarts after kill -9"
    ADOPT_EXPECTED=$((ADOPT_EXPECTED + 1))
  elif (( r < 40 )); then  # a daemon killed within 0-20 ms of its start
    node=$([[ $((RANDOM % 2)) = 0 ]] && echo control || echo planner)
    kill9 "${DPID[$node]}"
    ip netns exec "$(ns_of "$node")" "$BIN/ccommd" --node "$node" --no-rt -c "$CONFIG" \
      >>"$WORK/ccommd-$node.log" 2>&1 &
    p=$!
    sleep "0.0$((RANDOM % 20 / 10))$((RANDOM % 10))"
    kill9 $p
    KILLS[ccommd-$node-at-start]=$(( ${KILLS[ccommd-$node-at-start]:-0} + 1 ))
    start_daemon "$node" || not_ok "iteration $i: ccommd $node starts after a kill during start-up"
  elif (( r < 45 )); then  # control restarted with another configuration, and back
    kill9 "${DPID[control]}"
    DAEMON_CONFIG=$WORK/other.xml start_daemon control || not_ok "iteration $i: ccommd with the other config"
    sleep 0.3
    kill9 "${DPID[control]}"
    start_daemon control || not_ok "iteration $i: ccommd back on the first config"
    KILLS[config-change]=$(( ${KILLS[config-change]:-0} + 1 ))
  elif (( r < 55 )); then  # a writer in a tight loop, killed mid-stream: likely mid-copy
    spawn "$WORK/hammer.$i.log" planner "$WORK/torture" -n planner write t_local --rate 0
    p=$!
    sleep "0.0$((RANDOM % 5 + 1))"
    kill9 $p
    KILLS[hammer]=$(( ${KILLS[hammer]:-0} + 1 ))
  else  # a client
    c=${CLIENTS[$((RANDOM % ${#CLIENTS[@]}))]}
    kill9 "${CPID[$c]}"
    KILLS[$c]=$(( ${KILLS[$c]:-0} + 1 ))
    start_client "$c"
  fi
done
check_clients
note "kills: $(for k in "${!KILLS[@]}"; do printf '%s=%s ' "$k" "${KILLS[$k]}"; done)"

# Quiet period: everything must flow again.
sleep 2
check_clients
check "no reader saw a corrupt value (validated every value; $CORRUPT corrupt)" [ "$CORRUPT" -eq 0 ]
check "no client died on its own ($UNEXPECTED)" [ "$UNEXPECTED" -eq 0 ]
check "both ccommd running after the loop" daemon_alive control
check "planner ccommd running after the loop" daemon_alive planner
adopted=$(cat "$WORK"/ccommd-*.log | grep -c 're-adopted')
created=$(cat "$WORK"/ccommd-*.log | grep -c '(created)')
figure "ccommd starts: $adopted re-adopted the existing segment, $created created one"
check "restarted daemons re-adopted their segments ($adopted >= $ADOPT_EXPECTED)" [ "$adopted" -ge "$ADOPT_EXPECTED" ]
segs=$(ls /dev/shm | grep "^$TAG\." | grep -v '\.lock$' | grep -vc '\.view$')  # each node's lock stays (ccommd(8))
views=$(ls /dev/shm | grep -c "^$TAG\..*\.view$")  # each ccommd start replaces its node's system view
check "no stale segment left behind (2 segments, 2 system views: $(ls /dev/shm | grep "^$TAG\." | tr '\n' ' '))" \
  [ "$segs" -eq 2 -a "$views" -eq 2 ]

# End to end and local: new values arrive at the planner and locally, fresh.
seq_of() { cli "$1" echo "$2" --once | sed -n 's/.* seq=\([0-9]*\).*/\1/p'; }
status_of() { cli "$1" echo "$2" --once | grep -oE ' (fresh|stale|never)( |$)' | tr -d ' '; }
a=$(seq_of planner t_state); la=$(seq_of control t_state); lo=$(seq_of planner t_local)
all_moved() {  # bounded by wait_for: a starved writer on a loaded machine needs longer than 0.5 s
  b=$(seq_of planner t_state); lb=$(seq_of control t_state); lp=$(seq_of planner t_local)
  [ "${b:-0}" -gt "${a:-0}" ] && [ "${lb:-0}" -gt "${la:-0}" ] && [ "${lp:-0}" -gt "${lo:-0}" ] &&
    [ "$(status_of planner t_state)" = fresh ]
}
sleep 0.5
wait_for 20 all_moved
check "values flow end to end after the loop (t_state at planner: seq $a -> $b, $(status_of planner t_state))" \
  [ "${b:-0}" -gt "${a:-0}" -a "$(status_of planner t_state)" = fresh ]
check "local writes succeed after the loop (t_state at control: $la -> $lb; t_local at planner: $lo -> $lp)" \
  [ "${lb:-0}" -gt "${la:-0}" -a "${lp:-0}" -gt "${lo:-0}" ]

# Final reports of the clients still running.
for c in "${CLIENTS[@]}"; do kill -TERM "${CPID[$c]}" 2>/dev/null; done
for c in "${CLIENTS[@]}"; do wait "${CPID[$c]}" 2>/dev/null; done
values=0; busy=0; full=0; order=0
# Reopens: the highest count each client instance reported (killed ones included).
reopens=$(cat "$WORK"/[wc]_*.log | "$CCOMM_PYTHON" -c 'import json,sys
print(sum(json.loads(l).get("reopens", 0) for l in sys.stdin if l.startswith("{") and "\"final\"" in l))')
reopens_seen=$(for f in "$WORK"/[wc]_*.log; do grep -o '"reopens":[0-9]*' "$f" | cut -d: -f2 | sort -n | tail -n1; done |
  awk '{s+=$1} END {print s+0}')
# Values checked by every reader instance (the killed ones reported once a second).
values_all=$(for f in "$WORK"/c_*.log; do grep -o '"values":[0-9]*' "$f" | cut -d: -f2 | sort -n | tail -n1; done |
  awk '{s+=$1} END {print s+0}')
for f in "$WORK"/*.log; do
  line=$(grep '"final"' "$f" | tail -n1)
  [[ -n $line ]] || continue
  read -r v _ b fu o < <("$CCOMM_PYTHON" -c 'import json,sys; d=json.loads(sys.argv[1])
print(d.get("values",0), d.get("reopens",0), d.get("busy",0), d.get("full",0), d.get("order_violations",0))' "$line")
  values=$((values + v)); busy=$((busy + b)); full=$((full + fu)); order=$((order + o))
done
stats control; stats planner
reclaimed() { "$CCOMM_PYTHON" -c 'import json,sys; print(json.load(open(sys.argv[1]))["counters"].get("slots_reclaimed","n/a"))' "$WORK/stats-$1.json"; }
figure "values validated: $values_all (at least; $values by the readers alive at the end); reopens after a" \
       "segment change: $reopens_seen; writes refused busy: $busy, full: $full (surviving writers); slots of" \
       "killed writers reclaimed by ccommd: control $(reclaimed control), planner $(reclaimed planner)"
check "readers validated values ($values > 0)" [ "$values" -gt 0 ]
check "no value seen out of order per writer ($order)" [ "$order" -eq 0 ]
if [[ ${KILLS[config-change]:-0} -gt 0 ]]; then
  check "clients reopened after their segment was replaced ($reopens_seen reopens)" [ "$reopens_seen" -gt 0 ]
fi
finish
