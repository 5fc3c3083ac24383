#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fault injection between two boards: control and planner are joined through a middle
# namespace where tests/reliability/impair.c (a user-space netem; see its header for why
# not tc netem) applies, phase by phase: 10% loss, 10% duplication, reordering, 10%
# corruption, 50 ms jitter, all of them at once, then a black hole. Traffic: self-checking
# int64 arrays (state 1 kHz, events 300 Hz) control -> planner, a periodic signal, and
# setpoints planner -> control.
#
# Run twice: without authentication (corruption left out: without a MAC nothing but the
# link's CRC protects the payload) and with a pre-shared key. Checks per phase, in both
# directions, exactly: every delivered frame counted once; losses, duplicates, late
# frames and corrupted frames each show up in the right counter. Throughout: no corrupt
# value reaches an app, events are all delivered or counted lost, stale status and peer
# loss are detected within stale_after_ms / peer_timeout_ms.
#
#   NETEM_MODES (default "plain auth"); NETEM_SECONDS (default 3) per phase; NETEM_STALE_SLACK_MS (default 15): allowed
#   polling/scheduling delay of the reading app on top of stale_after_ms (the status
#   itself is checked exactly: no read says fresh past stale_after_ms);
#   NETEM_SUPERVISION_SLACK_MS (default 100): the same for ccommd's 10 ms supervision
#   tick (peer lost, stale transition counted), which runs SCHED_OTHER under --no-rt.
source "$(dirname "$0")/lib.sh"
require_root
require_build
build_tool impair
build_torture
SECS=${NETEM_SECONDS:-3}
SLACK=${NETEM_STALE_SLACK_MS:-15}
SUP_SLACK=${NETEM_SUPERVISION_SLACK_MS:-100}

SNAPS=()
# snap NAME: clean link, let late frames land, hold everything, read both daemons.
snap() {
  local d=$WORK/snap-${#SNAPS[@]}-$1
  mkdir -p "$d"
  imp "set loss=0 dup=0 reorder=0 corrupt=0 delay=0 jitter=0" >/dev/null
  sleep 0.15  # > the largest delay of any phase (50 ms)
  imp pause >/dev/null
  sleep 0.03
  stats_json planner >"$d/planner.json" &
  local j1=$!
  stats_json control >"$d/control.json" &
  local j2=$!
  local dp dc
  dp=$(sock_drops planner)
  dc=$(sock_drops control)
  wait $j1 $j2
  echo "{\"planner\": $dp, \"control\": $dc}" >"$d/drops.json"
  imp resume >"$d/imp.json"
  SNAPS+=("$d")
}
# phase KIND "impair settings": runs one phase and checks it against the last snapshot.
phase() {
  imp "set $2" >/dev/null
  sleep "$SECS"
  snap "$MODE-$1"
  evaluate "$1"
}
# evaluate KIND: checks the interval between the last two snapshots.
evaluate() {
  local kind=$1
  local n=${#SNAPS[@]} prev2=-
  (( n >= 3 )) && prev2=${SNAPS[n - 3]}
  local line
  while IFS= read -r line; do
    case $line in
      "CHECK 1 "*) ok "$MODE: ${line#CHECK 1 }" ;;
      "CHECK 0 "*) not_ok "$MODE: ${line#CHECK 0 }" ;;
      "FIGURE "*) figure "$MODE: ${line#FIGURE }" ;;
      *) not_ok "$MODE: phase_check: $line" ;;
    esac
  done < <("$CCOMM_PYTHON" "$REL_DIR/phase_check.py" "$kind" "$AUTH" "$prev2" "${SNAPS[n - 2]}" "${SNAPS[n - 1]}" 2>&1)
}
jfield() {  # jfield FILE KEY: a field of the line with "final" in FILE
  "$CCOMM_PYTHON" -c 'import json,sys
for l in open(sys.argv[1]):
    if "\"final\"" in l or "\"stale\"" in l: d=json.loads(l)
print(d.get(sys.argv[2], ""))' "$1" "$2" 2>/dev/null
}
sigstat() {  # sigstat NODE SIGNAL FIELD: a field of a signal in ccomm stats --json
  stats_json "$1" | "$CCOMM_PYTHON" -c 'import json,sys
for s in json.load(sys.stdin)["signals"]:
    if s["name"] == sys.argv[1]: print(s[sys.argv[2]])' "$2" "$3"
}

run_mode() {  # run_mode plain|auth
  MODE=$1
  AUTH=0
  DAEMON_CONFIG=$CONFIG
  if [[ $MODE = auth ]]; then
    AUTH=1
    head -c 32 /dev/urandom >"$WORK/auth.key"
    chmod 600 "$WORK/auth.key"
    sed "s|<network |<network auth_key_file=\"$WORK/auth.key\" |" "$CONFIG" >"$WORK/auth.xml"
    DAEMON_CONFIG=$WORK/auth.xml
  fi
  rm -f /dev/shm/"$TAG".*
  start_daemon control || { not_ok "$MODE: ccommd control starts"; return; }
  start_daemon planner || { not_ok "$MODE: ccommd planner starts"; return; }
  # Checkers first (events: they must see every event from the first one on).
  spawn "$WORK/$MODE-cs.log" planner "$WORK/torture" -n planner check t_state
  local cs=$!
  spawn "$WORK/$MODE-ce.log" planner "$WORK/torture" -n planner check t_event
  local ce=$!
  sleep 0.3
  spawn "$WORK/$MODE-ws.log" control "$WORK/torture" -n control write t_state --rate 1000
  local ws=$!
  spawn "$WORK/$MODE-we.log" control "$WORK/torture" -n control write t_event --rate 300
  local we=$!
  # beat: written at 1 kHz, forwarded every 5 ms (periodic: the newest value per period).
  spawn "$WORK/$MODE-beat.log" control "$BIN/ccomm" --node control pub beat 1 --rate 1000 --count 100000000
  local beat=$!
  spawn "$WORK/$MODE-pong.log" planner "$BIN/ccomm" --node planner pub pong 1.5 --rate 500 --count 100000000
  local pong=$!
  sleep 0.5
  snap "$MODE-start"

  phase loss "loss=10"
  phase dup "dup=10"
  phase reorder "reorder=25 delay=10"
  [[ $AUTH = 1 ]] && phase corrupt "corrupt=10"
  phase jitter "jitter=50"
  phase all "loss=10 dup=10 reorder=10 delay=5 corrupt=$((AUTH * 10)) jitter=50"

  # Black hole: how fast do apps see stale values and ccommd a lost peer? blackhole.py
  # drops everything and watches ccommd; torture reads as an app would.
  spawn "$WORK/$MODE-stale-beat.json" planner "$WORK/torture" -n planner stale beat --timeout 10
  local sb=$!
  spawn "$WORK/$MODE-stale-pong.json" control "$WORK/torture" -n control stale pong --timeout 10
  local sp=$!
  sleep 0.3
  "$CCOMM_PYTHON" "$REL_DIR/blackhole.py" --fifo "$WORK/imp.in" --ns "$NS_P" --ccomm "$BIN/ccomm" --node planner \
    --signal beat >"$WORK/$MODE-blackhole.json" 2>&1
  wait $sb $sp
  local beat_ms pong_ms pong_safe down_ms sup_ms up_ms
  beat_ms=$(jfield "$WORK/$MODE-stale-beat.json" detected_after_ms)
  pong_ms=$(jfield "$WORK/$MODE-stale-pong.json" detected_after_ms)
  pong_safe=$(jfield "$WORK/$MODE-stale-pong.json" safe_value)
  down_ms=$(json_get "$WORK/$MODE-blackhole.json" down_ms)
  sup_ms=$(json_get "$WORK/$MODE-blackhole.json" stale_ms)
  up_ms=$(json_get "$WORK/$MODE-blackhole.json" up_ms)
  figure "$MODE: black hole: apps read stale after: beat (periodic 5 ms) $beat_ms ms, pong (event-driven)" \
         "$pong_ms ms, safe value $pong_safe (stale_after_ms 20); ccommd counted the stale transition after" \
         "$sup_ms ms and declared the peer lost after $down_ms ms (peer_timeout_ms 300); peer back $up_ms ms" \
         "after the link returned (stats polled every 5 ms)"
  local ages
  ages="beat: fresh up to $(jfield "$WORK/$MODE-stale-beat.json" max_fresh_age_ms) ms, stale from"
  ages+=" $(jfield "$WORK/$MODE-stale-beat.json" first_stale_age_ms) ms; pong: fresh up to"
  ages+=" $(jfield "$WORK/$MODE-stale-pong.json" max_fresh_age_ms), stale from $(jfield "$WORK/$MODE-stale-pong.json" first_stale_age_ms)"
  check "$MODE: no read says fresh past stale_after_ms, the first stale read is past it ($ages)" \
    "$CCOMM_PYTHON" -c 'import json,sys
ok = True
for f in sys.argv[1:3]:
    d = [json.loads(l) for l in open(f) if l.startswith("{")][-1]
    ok &= "first_stale_age_ms" in d and d["max_fresh_age_ms"] <= d["stale_after_ms"] < d["first_stale_age_ms"]
sys.exit(0 if ok else 1)' "$WORK/$MODE-stale-beat.json" "$WORK/$MODE-stale-pong.json"
  check "$MODE: apps see stale within stale_after_ms + ${SLACK} ms of the last value (beat $beat_ms, pong $pong_ms)" \
    "$CCOMM_PYTHON" -c 'import sys; v=[float(x) for x in sys.argv[1:3]]; sys.exit(0 if all(20 <= x <= 20 + float(sys.argv[3]) for x in v) else 1)' \
    "${beat_ms:-0}" "${pong_ms:-0}" "$SLACK"
  check "$MODE: a stale setpoint reads as its safe value" [ "$pong_safe" = True ]
  # Measured from the cut, not from the last frame, which came up to one 5 ms period
  # (plus the 5 ms stats poll) earlier: hence the lower bound 20 - 6 ms.
  check "$MODE: ccommd counts the stale transition within stale_after_ms + $SUP_SLACK ms ($sup_ms)" \
    "$CCOMM_PYTHON" -c 'import sys; sys.exit(0 if 14 <= float(sys.argv[1]) <= 20 + float(sys.argv[2]) else 1)' "${sup_ms:--1}" "$SUP_SLACK"
  check "$MODE: peer declared lost within peer_timeout_ms + $SUP_SLACK ms ($down_ms)" \
    "$CCOMM_PYTHON" -c 'import sys; sys.exit(0 if 300 <= float(sys.argv[1]) <= 300 + float(sys.argv[2]) else 1)' "${down_ms:--1}" "$SUP_SLACK"
  check "$MODE: peer back within a heartbeat period + 50 ms after the link returns ($up_ms)" \
    "$CCOMM_PYTHON" -c 'import sys; sys.exit(0 if 0 <= float(sys.argv[1]) <= 150 else 1)' "${up_ms:--1}"
  sleep 1
  snap "$MODE-blackhole"
  evaluate all  # black hole and recovery: conservation (the gap is seen on recovery)
  phase clean ""

  # Events: every one written is delivered or counted lost; no app saw a bad value.
  kill -TERM $ws $we $pong $beat 2>/dev/null
  wait $ws $we $pong $beat 2>/dev/null
  sleep 0.5
  kill -TERM $cs $ce 2>/dev/null
  wait $cs $ce 2>/dev/null
  local written rx lost ovf got
  written=$(jfield "$WORK/$MODE-we.log" ok)
  got=$(jfield "$WORK/$MODE-ce.log" values)
  rx=$(sigstat planner t_event rx); lost=$(sigstat planner t_event lost); ovf=$(sigstat planner t_event overflow)
  figure "$MODE: events: written $written, stored at planner $rx, counted lost $lost, read by the app $got," \
         "reader overruns $ovf"
  check "$MODE: every event written is stored or counted lost ($written == $rx + $lost)" \
    [ "${written:-x}" = $((rx + lost)) ]
  check "$MODE: the app read every stored event or saw it counted as overrun ($rx == $got + $ovf)" \
    [ "$rx" = $((got + ovf)) ]
  for f in cs ce; do
    figure "$MODE: checker $f: $(grep '"final"' "$WORK/$MODE-$f.log")"
    check "$MODE: checker $f saw values, none corrupt, none out of order" \
      "$CCOMM_PYTHON" -c 'import json,sys; c=json.loads(sys.argv[1] or "{}")
sys.exit(0 if c.get("values", 0) > 100 and c.get("corrupt") is False and c.get("order_violations") == 0 else 1)' \
      "$(grep '"final"' "$WORK/$MODE-$f.log")"
  done
  check "$MODE: both ccommd still running" daemon_alive control
  check "$MODE: planner ccommd still running" daemon_alive planner
  stop_daemon control
  stop_daemon planner
}

make_impaired_pair
imp_start 7
for m in ${NETEM_MODES:-plain auth}; do run_mode "$m"; done
finish
