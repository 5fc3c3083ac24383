#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Junk flood: tests/reliability/flood.c sends random, truncated and broken-header frames
# (and empty datagrams over UDP) at the planner's ccommd (raw EtherType, then UDP port), paced and then as fast as it
# can, while control pings the planner through ccomm and a local app on the planner
# writes and reads its own signal. Checks, per phase:
#   - every frame that reached the planner's eth0 is accounted for exactly:
#     rx_packets = frames ccommd counted (rx, bad, ...) + frames dropped at its socket;
#   - every junk frame is accounted for exactly: sent = frames_bad + socket drops +
#     veth drops - genuine frames lost (seq gaps);
#   - both daemons keep running, the peer is alive again right after the flood, the
#     local app is served all along without a corrupt value, ccommd's memory is flat.
#
#   FLOOD_SECONDS (default 4) per phase; FLOOD_RATE (default 150000) for the paced
#   phases; FLOOD_MIN_RATE (default 100000): the rate the fastest phase must reach.
source "$(dirname "$0")/lib.sh"
require_root
require_build
build_tool flood
build_torture
SECS=${FLOOD_SECONDS:-4}
RATE=${FLOOD_RATE:-150000}
MIN_RATE=${FLOOD_MIN_RATE:-100000}
BEST_RATE=0

# The control daemon sends genuine frames all the time (heartbeats, the periodic
# "beat"): it is paused while the planner's counters are read, so that nothing arrives
# between reading the interface and reading ccommd (a pause far below peer_timeout_ms).
quiet_snapshot() {
  kill -STOP "${DPID[control]}"
  sleep 0.02
  snapshot planner
  kill -CONT "${DPID[control]}"
}

# flood_phase LABEL FLOOD-ARGS...: one flood against the planner, pinged meanwhile.
flood_phase() {
  local label=$1; shift
  quiet_snapshot
  local rx0=$SNAP_RX drops0=$SNAP_DROPS tot0 bad0 lost0 txd0 sdc0
  tot0=$(frames_total planner); bad0=$(counter planner frames_bad); lost0=$(peer planner frames_lost)
  sdc0=$(counter planner socket_drops)
  txd0=$(tx_dropped control)
  in_ns control "$WORK/flood" "$@" --duration "$SECS" >"$WORK/flood-$label.json" 2>&1 ||
    { not_ok "$label: flooder failed: $(cat "$WORK/flood-$label.json")"; return; }
  sleep 0.4  # ccommd drains its socket; the next heartbeat reveals any gap
  quiet_snapshot
  local sent rate
  sent=$(json_get "$WORK/flood-$label.json" sent); rate=$(json_get "$WORK/flood-$label.json" rate)
  local rx=$((SNAP_RX - rx0)) drops=$((SNAP_DROPS - drops0)) tot=$(( $(frames_total planner) - tot0 ))
  local bad=$(( $(counter planner frames_bad) - bad0 )) lost=$(( $(peer planner frames_lost) - lost0 ))
  local txd=$(( $(tx_dropped control) - txd0 ))
  (( ${rate%.*} > BEST_RATE )) && BEST_RATE=${rate%.*}
  figure "$label: flooder sent $sent junk frames ($rate/s); planner eth0 rx $rx; ccommd counted $tot" \
         "(frames_bad +$bad); dropped at ccommd's socket $drops, at the veth $txd; genuine frames lost $lost"
  check "$label: eth0 rx == counted by ccommd + socket drops ($rx == $tot + $drops)" [ "$rx" -eq $((tot + drops)) ]
  check "$label: junk sent == frames_bad + socket drops + veth drops - genuine lost ($sent == $bad + $drops + $txd - $lost)" \
    [ "$sent" -eq $((bad + drops + txd - lost)) ]
  # ccommd reads the kernel's count every 100 ms; the 0.4 s pause above covers that.
  local sdc=$(( $(counter planner socket_drops) - sdc0 ))
  check "$label: ccommd's socket_drops counter == the kernel's drops at its socket ($sdc == $drops)" [ "$sdc" -eq "$drops" ]
  check "$label: planner ccommd alive" daemon_alive planner
}

run_transport() {  # run_transport raw|udp
  local t=$1 extra=()
  [[ $t = udp ]] && extra=(--transport udp)
  start_daemon control "${extra[@]}" || { not_ok "$t: ccommd control starts"; return; }
  start_daemon planner "${extra[@]}" || { not_ok "$t: ccommd planner starts"; return; }
  local pid_p=${DPID[planner]}
  # Ping/pong across both phases (ccomm-latency expects fresh segments: see stop below).
  spawn "$WORK/echo-$t.json" planner "$BIN/ccomm-latency" -n planner --mode echo --send pong --recv ping \
    --rate 500 --duration 3600
  local echo=$!
  spawn "$WORK/ping-$t.json" control "$BIN/ccomm-latency" -n control --mode ping --send ping --recv pong \
    --rate 500 --duration $((2 * SECS + 3)) --warmup 0.2
  local ping=$!
  # A local app on the flooded node: writes at 2 kHz, another process checks every value.
  spawn "$WORK/lw-$t.log" planner "$WORK/torture" -n planner write t_local --rate 2000
  local lw=$!
  spawn "$WORK/lc-$t.log" planner "$WORK/torture" -n planner check t_local
  local lc=$!
  wait_for 20 peer_up planner
  check "$t: peer up before the flood" [ "$(peer planner alive)" = true ]
  local mem0; mem0=$(rss "$pid_p")

  if [[ $t = raw ]]; then
    flood_phase raw-paced --ifname eth0 --rate "$RATE"
    flood_phase raw-max --ifname eth0 --rate 0
  else
    flood_phase udp-paced --udp 10.42.0.2 --port 47800 --rate "$RATE"
    flood_phase udp-max --udp 10.42.0.2 --port 47800 --rate 0
  fi

  local up=0 i
  for i in $(seq 20); do stats planner; [[ $(peer planner alive) = true ]] && { up=1; break; }; sleep 0.05; done
  check "$t: peer alive right after the floods" [ $up -eq 1 ]
  figure "$t: peer down transitions during the floods (planner's view): $(peer planner down_transitions)"
  local mem1; mem1=$(rss "$pid_p")
  figure "$t: planner ccommd VmRSS VmHWM (kB) before: $mem0, after: $mem1"
  check "$t: planner ccommd memory flat (VmHWM growth <= 256 kB)" [ $(( ${mem1#* } - ${mem0#* } )) -le 256 ]

  kill -TERM $lw $lc 2>/dev/null
  wait $lw $lc $ping 2>/dev/null
  kill -TERM $echo 2>/dev/null
  wait $echo 2>/dev/null
  figure "$t: ping/pong through both floods (RTT/2 in ns): $(tail -n1 "$WORK/ping-$t.json")"
  local lwf lcf
  lwf=$(grep '"final"' "$WORK/lw-$t.log"); lcf=$(grep '"final"' "$WORK/lc-$t.log")
  figure "$t: local writer: $lwf"
  figure "$t: local checker: $lcf"
  check "$t: local app on the flooded node served throughout, no corrupt value" \
    "$CCOMM_PYTHON" -c 'import json,sys; w=json.loads(sys.argv[1] or "{}"); c=json.loads(sys.argv[2] or "{}")
sys.exit(0 if w.get("ok", 0) >= 2000 * 2 * float(sys.argv[3]) * 0.8 and w.get("busy") == 0 and
         c.get("values", 0) > 100 and c.get("corrupt") is False and c.get("order_violations") == 0 else 1)' \
    "$lwf" "$lcf" "$SECS"
  check "$t: control ccommd alive" daemon_alive control
  stop_daemon planner; check "$t: planner ccommd exits cleanly on SIGTERM after the floods" [ $? -eq 0 ]
  stop_daemon control
  rm -f /dev/shm/"$TAG".*  # the next run starts from fresh segments
}

make_pair
run_transport raw
run_transport udp
figure "fastest flood: $BEST_RATE frames/s"
check "a flood phase reached >= $MIN_RATE frames/s ($BEST_RATE)" [ "$BEST_RATE" -ge "$MIN_RATE" ]
finish
