# SPDX-License-Identifier: Apache-2.0
# Sourced by tests/windows/run (step 5): ccommd.exe under Wine against a Linux ccommd.
#   a. ccommd.exe --check: a valid file, a Windows node on raw Ethernet ("Linux-only"),
#      and a bad file: the same message and exit status as the Linux ccommd.
#   b. Two network namespaces joined by a veth pair: the Linux ccommd (node control,
#      10.42.0.1) in one, ccommd.exe under Wine (node planner, 10.42.0.2) in the other,
#      examples/setup-simulation-udp.xml. ccomm-latency --mode ping (Linux: 36 doubles at
#      1 kHz) against ccomm-latency.exe --mode echo (Windows: 9 doubles back): every value
#      sent arrives (the receiving ccommd's rx equals the sending ccommd's tx, per signal,
#      and no value is lost); p50 one-way latency is RTT/2 on the Linux clock.
#      Wine timing is not Windows timing.
#   c. Junk datagrams (random bytes, an empty one) to each ccommd: counted as frames_bad
#      alike, no receive error, both keep running.
#   d. The link cut: a Windows reader of a Linux signal sees it fresh while values come
#      and stale (never fresh when older than stale_after_ms = 20 ms) once they stop.
# Needs root (namespaces) and the Linux release build (build/release: ccommd, ccomm,
# ccomm-latency); without them these checks are reported as skipped.
# Uses from run: check, say, wine, winepath_of, WINE, W, BUILD, SRC, ns_l, ns_w.

LBIN=${CCOMM_LINUX_BIN:-$SRC/build/release/bin}  # the Linux side (ccommd, ccomm, ccomm-latency)
WBIN=$BUILD/bin
sim=$SRC/examples/setup-simulation-udp.xml

# ---- a. --check ------------------------------------------------------------------------
check_valid() {
  local out; out=$(cd "$SRC" && wine "$WBIN/ccommd.exe" --check examples/setup-simulation-udp.xml 2>&1)
  echo "$out" | grep -q '^examples/setup-simulation-udp.xml: ok (2 nodes, 45 signals' || { echo "$out"; return 1; }
}
check "ccommd.exe --check: the setup-simulation (UDP) is valid" check_valid
check_raw() {
  local out rc
  out=$(cd "$SRC" && wine "$WBIN/ccommd.exe" --check examples/setup-simulation.xml --node planner 2>&1); rc=$?
  [[ $rc -eq 1 ]] && echo "$out" | grep -q \
    '^examples/setup-simulation.xml:[0-9]*: error: node .planner. uses transport="raw": raw Ethernet is Linux-only' ||
    { echo "exit $rc: $out"; return 1; }
  # Starting it says the same (and fails before any socket).
  out=$(cd "$SRC" && wine "$WBIN/ccommd.exe" -c examples/setup-simulation.xml --node planner --no-rt 2>&1); rc=$?
  [[ $rc -ne 0 ]] && echo "$out" | grep -q 'raw Ethernet is Linux-only' || { echo "start: exit $rc: $out"; return 1; }
}
check "ccommd.exe --check / start: a Windows node on raw Ethernet is refused (Linux-only)" check_raw

# ---- a2. ccommd.exe as a Windows service (Wine's services.exe) ---------------------------
# Wine ends its services when its last ordinary process exits: a console (cmd reading a
# fifo held open) keeps the session while the service runs.
svc_state() { wine sc query "$1" 2>/dev/null | tr -d '\r' | sed -n 's/^ *\(STATE\|SERVICE_EXIT_CODE\) *: \([0-9]*\).*/\2/p' | tr '\n' ' '; }
svc_wait() {  # NAME STATE: waits (bounded) until the service is in STATE (4 running, 1 stopped)
  local deadline=$((SECONDS + 60))
  until [[ $(svc_state "$1") == "$2 "* ]]; do [[ $SECONDS -lt $deadline ]] || return 1; sleep 0.3; done
}
service() {
  local name=ccommd-t$$ log=$WBIN/ccommd.log keeper rc=0
  rm -f "$log"
  mkfifo "$W/keep"
  "$WINE" cmd <"$W/keep" >/dev/null 2>&1 &
  keeper=$!
  exec 8>"$W/keep"  # cmd ends when this closes
  wine sc create "$name" binPath= "$(winepath_of "$WBIN/ccommd.exe") --service -c $(winepath_of "$SRC/examples/local-only.xml") --node robot --no-rt" >/dev/null &&
    wine sc start "$name" >/dev/null && svc_wait "$name" 4 || rc=1
  local deadline=$((SECONDS + 60))
  until [[ $rc -ne 0 ]] || wine "$WBIN/ccomm.exe" --node robot stats --json 2>/dev/null | grep -q '"daemon_alive":true'; do
    [[ $SECONDS -lt $deadline ]] || { echo "service running, but no live segment"; rc=1; }
    sleep 0.3
  done
  [[ $rc -eq 0 ]] && { wine sc stop "$name" >/dev/null; svc_wait "$name" 1 || rc=1; }
  local state; state=$(svc_state "$name")
  say "  service: after sc stop: state/exit code '$state'; log: $(grep -c . "$log" 2>/dev/null) lines, last '$(tail -1 "$log" 2>/dev/null | tr -d '\r')'"
  local text; text=$(tr -d '\r' <"$log" 2>/dev/null)  # the C runtime's text mode writes CR LF
  [[ $state == "1 0 " ]] && grep -q "node 'robot'" <<<"$text" && [[ $(tail -1 <<<"$text") == stopping ]] || rc=1
  # A bad configuration: the service stops at once with ccommd's exit status 1.
  wine sc delete "$name" >/dev/null
  wine sc create "$name" binPath= "$(winepath_of "$WBIN/ccommd.exe") --service -c $(winepath_of "$W/missing.xml") --no-rt" >/dev/null &&
    wine sc start "$name" >/dev/null
  svc_wait "$name" 1 && state=$(svc_state "$name")
  say "  service with a missing config: state/exit code '$state'"
  [[ $state == "1 1 " ]] || rc=1
  wine sc delete "$name" >/dev/null
  exec 8>&-
  wait "$keeper" 2>/dev/null
  return $rc
}
check "ccommd.exe --service under Wine's service manager: sc start runs it, sc stop stops it cleanly, a bad config stops it with status 1" service

if [[ ! -x $LBIN/ccommd || ! -x $LBIN/ccomm || ! -x $LBIN/ccomm-latency ]]; then
  say "SKIP Wine <-> Linux checks: no Linux release build in build/release (scripts/build release)"
  return 0
fi
check_bad_config() {
  mkdir -p "$W/bad"
  # A consumer that is no node, and a stale_after_ms that is no number.
  sed -e '0,/consumers="planner"/s//consumers="nobody"/' -e '0,/stale_after_ms="20"/s//stale_after_ms="soon"/' \
      "$sim" >"$W/bad/bad.xml"
  local lout wout lrc wrc
  lout=$(cd "$W/bad" && "$LBIN/ccommd" --check bad.xml 2>&1); lrc=$?
  wout=$(cd "$W/bad" && wine "$WBIN/ccommd.exe" --check bad.xml 2>&1); wrc=$?
  wout=$(tr -d '\r' <<<"$wout")  # the C runtime's text mode writes CR LF
  [[ $lrc -eq 1 && -n $lout && $lout == "$wout" ]] ||
    { echo "Linux (exit $lrc):"; echo "$lout"; echo "Windows (exit $wrc):"; echo "$wout"; return 1; }
  say "  bad config, both say ($(echo "$lout" | wc -l) lines): $(echo "$lout" | head -1)"
}
check "a bad config: ccommd.exe --check prints what the Linux ccommd prints (file:line errors)" check_bad_config

if [[ $(id -u) -ne 0 ]] || ! command -v ip >/dev/null; then
  say "SKIP Wine <-> Linux two-node checks: need root and iproute2 for the network namespaces"
  return 0
fi

# ---- b. two nodes ----------------------------------------------------------------------
ns_l=ccomm-w$$-linux ns_w=ccomm-w$$-wine
"$SRC/scripts/netns-pair" up "$ns_l" "$ns_w" --ip-a 10.42.0.1/24 --ip-b 10.42.0.2/24 ||
  { check "network namespaces joined by a veth pair (scripts/netns-pair)" false; return 0; }
# Arrays, not functions: a command started in the background through them has $! = its pid.
in_l=(ip netns exec "$ns_l")
# Wine's sockets are made by its wineserver: it must live in the Windows namespace, so
# the one of the steps before is stopped and the next Wine process starts it there.
/usr/lib/wine/wineserver -k 2>/dev/null; /usr/lib/wine/wineserver -w 2>/dev/null
in_w=(ip netns exec "$ns_w" timeout "${WINE_TIMEOUT:-300}" "$WINE")
simw=$(winepath_of "$sim")
lstats() { "$LBIN/ccomm" --node control stats --json; }
wstats() { "${in_w[@]}" "$WBIN/ccomm.exe" --node planner stats --json | tr -d '\r'; }

"${in_l[@]}" "$LBIN/ccommd" --node control -c "$sim" --no-rt >"$W/linux-ccommd.log" 2>&1 &
lpid=$!
"${in_w[@]}" "$WBIN/ccommd.exe" --node planner -c "$simw" --no-rt >"$W/wine-ccommd.log" 2>&1 &
wpid=$!
peers_up() {
  local deadline=$((SECONDS + 120))
  until lstats 2>/dev/null | grep -q '"name":"planner","alive":true' &&
        wstats 2>/dev/null | grep -q '"name":"control","alive":true'; do
    [[ $SECONDS -lt $deadline ]] && kill -0 $lpid 2>/dev/null && kill -0 $wpid 2>/dev/null ||
      { echo "Linux ccommd:"; cat "$W/linux-ccommd.log"; echo "ccommd.exe:"; cat "$W/wine-ccommd.log"; return 1; }
    sleep 0.2
  done
}
check "Linux ccommd and ccommd.exe (Wine) up, each sees the other as a peer" peers_up
kill -0 $lpid 2>/dev/null && kill -0 $wpid 2>/dev/null || return 0

# Per-signal tx (sending node) and rx/lost (receiving node) sums, from two stats snapshots.
counters() {  # BEFORE_TX AFTER_TX BEFORE_RX AFTER_RX: prints "tx rx lost mismatched signals coalesced"
  "$CCOMM_PYTHON" - "$@" <<'PY'
import json, sys
btx, atx, brx, arx = (json.loads(open(f).read()) for f in sys.argv[1:5])
sig = lambda s: {x["name"]: x for x in s["signals"]}
btx, atx, brx, arx = sig(btx), sig(atx), sig(brx), sig(arx)
names = [n for n in arx if arx[n]["rx"] or atx[n]["tx"] > btx[n]["tx"]]
tx = sum(atx[n]["tx"] - btx[n]["tx"] for n in names)
rx = sum(arx[n]["rx"] - brx[n]["rx"] for n in names)
# A gap in a signal's sequence numbers is a lost value unless the sending ccommd itself
# replaced it by a newer one before sending (coalesced: it ran late), as scripts/demo counts.
lost = sum(max((arx[n]["lost"] - brx[n]["lost"]) - (atx[n]["coalesced"] - btx[n]["coalesced"]), 0) for n in names)
coalesced = sum(atx[n]["coalesced"] - btx[n]["coalesced"] for n in names)
bad = [n for n in names if atx[n]["tx"] - btx[n]["tx"] != arx[n]["rx"] - brx[n]["rx"]]
print(tx, rx, lost, len(bad), len(names), coalesced)
PY
}
# Datagrams the kernel dropped at a namespace's UDP sockets (a full receive buffer: the
# receiving process did not read in time), the last column of /proc/net/udp.
udp_drops() { ip netns exec "$1" awk 'NR > 1 { n += $NF } END { print n + 0 }' /proc/net/udp /proc/net/udp6; }
# A direction's values are all there (rx == tx, 0 lost), or the missing ones are exactly
# those counted lost and fit in the datagrams the receiving socket's kernel dropped (at most
# 36 values each): a receiver starved on a loaded host (Wine's is not real time) loses at
# its socket, counted there and by ccomm, never silently.
delivered() {  # TX RX LOST BAD DROPS
  [[ $3 -eq 0 && $4 -eq 0 ]] && return 0
  [[ $5 -gt 0 && $(($1 - $2)) -eq $3 && $3 -le $(($5 * 36)) ]]
}
setup_simulation() {
  lstats >"$W/l0.json" && wstats >"$W/w0.json" || return 1
  local drops_w0 drops_l0; drops_w0=$(udp_drops "$ns_w"); drops_l0=$(udp_drops "$ns_l")
  # The echo (Windows) first; the ping's 5 s warm-up covers Wine's start-up.
  "${in_w[@]}" "$WBIN/ccomm-latency.exe" --node planner --mode echo --rate 1000 --duration 25 \
    >"$W/echo.json" 2>"$W/echo.err" &
  local echo_pid=$!
  "${in_l[@]}" "$LBIN/ccomm-latency" --node control --mode ping --rate 1000 --duration 15 --warmup 5 \
    --label "Linux -> Wine -> Linux" >"$W/ping.json" 2>"$W/ping.err" || { cat "$W/ping.err"; return 1; }
  kill "$echo_pid" 2>/dev/null; wait "$echo_pid" 2>/dev/null
  # Frames still in flight: wait (bounded) until the counters agree, then compare.
  local deadline=$((SECONDS + 30)) to_w to_l
  while :; do
    lstats >"$W/l1.json" && wstats >"$W/w1.json" || return 1
    to_w=$(counters "$W/l0.json" "$W/l1.json" "$W/w0.json" "$W/w1.json")
    to_l=$(counters "$W/w0.json" "$W/w1.json" "$W/l0.json" "$W/l1.json")
    read -r _ _ _ bw _ <<<"$to_w"; read -r _ _ _ bl _ <<<"$to_l"
    [[ ($bw -eq 0 && $bl -eq 0) || $SECONDS -ge $deadline ]] && break
    sleep 0.5
  done
  local p50 sent recv llost
  read -r p50 sent recv llost < <("$CCOMM_PYTHON" -c 'import json,sys; r=json.load(open(sys.argv[1]));
print(r["p50_ns"], r["sent"], r["received"], r["lost"])' "$W/ping.json")
  read -r txw rxw lostw badw nw cow <<<"$to_w"; read -r txl rxl lostl badl nl col <<<"$to_l"
  local dropw=$(($(udp_drops "$ns_w") - drops_w0)) dropl=$(($(udp_drops "$ns_l") - drops_l0))
  say "  Linux -> Windows: $nw signals, $txw values sent, $rxw received, $lostw lost, $badw signals with rx != tx" \
      "($cow coalesced by the sending ccommd: it ran late; $dropw datagrams dropped by the kernel at Wine's socket)"
  say "  Windows -> Linux: $nl signals, $txl values sent, $rxl received, $lostl lost, $badl signals with rx != tx" \
      "($col coalesced; $dropl datagrams dropped at the Linux socket)"
  [[ $lostw -eq 0 && $dropw -eq 0 ]] || say "  TODO: values lost at a receiving socket the kernel counted as full" \
      "(Wine's receiver is not real time; on a quiet host none are)"
  say "  ping (36 doubles) / echo (9 doubles) at 1 kHz, 10 s measured: $sent cycles, $recv echoed whole, $llost" \
      "cycles not echoed whole; p50 one-way (RTT/2) $(awk -v n="$p50" 'BEGIN{printf "%.0f", n/1000}') us" \
      "(Wine timing is not Windows timing)"
  [[ $nw -eq 36 && $nl -eq 9 && $txw -gt 0 && $txl -gt 0 && $recv -gt 0 ]] &&
    delivered "$txw" "$rxw" "$lostw" "$badw" "$dropw" && delivered "$txl" "$rxl" "$lostl" "$badl" "$dropl"
}
check "setup-simulation Linux <-> Wine, 36 + 9 doubles at 1 kHz: every value arrives (or is counted lost where the kernel dropped its datagram)" setup_simulation

# ---- c. junk ---------------------------------------------------------------------------
junk() {  # IP: 20 datagrams of random bytes and one empty one to IP:47800
  "$CCOMM_PYTHON" - "$1" <<'PY'
import os, socket, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
for i in range(20):
    s.sendto(os.urandom(16 + 37 * i), (sys.argv[1], 47800))
s.sendto(b"", (sys.argv[1], 47800))
PY
}
counter() { "$CCOMM_PYTHON" -c 'import json,sys; print(json.load(sys.stdin)["counters"][sys.argv[1]])' "$1"; }
junk_frames() {
  local wb lb we le wb2 lb2 we2 le2
  wb=$(wstats | counter frames_bad) && lb=$(lstats | counter frames_bad) || return 1
  we=$(wstats | counter recv_errors) && le=$(lstats | counter recv_errors) || return 1
  "${in_l[@]}" bash -c "$(declare -f junk); junk 10.42.0.2" && ip netns exec "$ns_w" bash -c "$(declare -f junk); junk 10.42.0.1" || return 1
  local deadline=$((SECONDS + 30))
  while :; do
    wb2=$(wstats | counter frames_bad); lb2=$(lstats | counter frames_bad)
    [[ $((wb2 - wb)) -ge 21 && $((lb2 - lb)) -ge 21 || $SECONDS -ge $deadline ]] && break
    sleep 0.3
  done
  we2=$(wstats | counter recv_errors); le2=$(lstats | counter recv_errors)
  say "  21 junk datagrams each: frames_bad +$((wb2 - wb)) on ccommd.exe, +$((lb2 - lb)) on Linux;" \
      "recv_errors +$((we2 - we)) / +$((le2 - le))"
  [[ $((wb2 - wb)) -eq 21 && $((lb2 - lb)) -eq 21 && $we2 -eq $we && $le2 -eq $le ]] &&
    kill -0 $lpid && kill -0 $wpid && peers_up
}
check "junk datagrams: counted as frames_bad alike by ccommd.exe and the Linux ccommd, both run on" junk_frames

# ---- d. the link cut -------------------------------------------------------------------
link_cut() {
  "${in_l[@]}" "$LBIN/ccomm" --node control pub wheel0_pos 1.5 --rate 1000 --count 120000 >/dev/null 2>&1 &
  local pub=$!
  "${in_w[@]}" "$WBIN/ccomm.exe" --node planner echo wheel0_pos --interval 5 -n 20000 --timeout 100 >"$W/cut.out" 2>&1 &
  local reader=$!
  local deadline=$((SECONDS + 60))
  until [[ $(grep -c ' fresh ' "$W/cut.out" 2>/dev/null) -ge 50 ]]; do
    [[ $SECONDS -lt $deadline ]] || { cat "$W/cut.out"; kill $pub $reader; return 1; }
    sleep 0.2
  done
  ip -n "$ns_l" link set eth0 down
  deadline=$((SECONDS + 60))
  until grep -q ' stale ' "$W/cut.out" 2>/dev/null; do
    [[ $SECONDS -lt $deadline ]] || { tail "$W/cut.out"; kill $pub $reader; return 1; }
    sleep 0.2
  done
  sleep 0.5  # a few more stale readings
  kill $pub $reader 2>/dev/null; wait $pub $reader 2>/dev/null
  ip -n "$ns_l" link set eth0 up
  tr -d '\r' <"$W/cut.out" | "$CCOMM_PYTHON" -c '
import re, sys
rows = [(m.group(1), int(m.group(2))) for m in (re.search(r" (fresh|stale)\*? seq=\d+ age_us=(-?\d+)", l) for l in sys.stdin) if m]
fresh_old = [a for s, a in rows if s == "fresh" and a > 20000]
stale_young = [a for s, a in rows if s == "stale" and a <= 20000]
first = next(i for i, (s, _) in enumerate(rows) if s == "stale")
print("windows:   %d readings: last fresh age %d us, first stale age %d us; fresh older than 20 ms: %d, stale younger: %d"
      % (len(rows), rows[first - 1][1], rows[first][1], len(fresh_old), len(stale_young)))
sys.exit(1 if fresh_old or stale_young or first == 0 else 0)'
}
check "link cut: the Windows reader sees the Linux signal stale after stale_after_ms (20 ms), never fresh older" link_cut

kill $lpid $wpid 2>/dev/null; wait $lpid $wpid 2>/dev/null

# ---- e. multicast ----------------------------------------------------------------------
# The same two nodes with fanout="multicast": each producer sends one frame per cycle to
# its own group (multicast_base + node ID), each consumer joins its producers' groups, so
# the Windows ccommd reads through a Winsock group membership on the veth.
sed 's|<network |<network fanout="multicast" |' "$sim" >"$W/multicast.xml"
simm=$(winepath_of "$W/multicast.xml")
"${in_l[@]}" "$LBIN/ccommd" --node control -c "$W/multicast.xml" --no-rt >"$W/linux-ccommd-m.log" 2>&1 &
lpid=$!
"${in_w[@]}" "$WBIN/ccommd.exe" --node planner -c "$simm" --no-rt >"$W/wine-ccommd-m.log" 2>&1 &
wpid=$!
multicast() {
  peers_up || return 1
  lstats >"$W/lm0.json" && wstats >"$W/wm0.json" || return 1
  # 2000 values each way at 200 Hz (10 s: Wine starts its echo in seconds): Linux -> the group
  # -> Windows, and back
  "${in_l[@]}" "$LBIN/ccomm" --node control pub wheel0_pos 1.25 --rate 200 --count 2000 >/dev/null &
  local lp=$!
  "${in_w[@]}" "$WBIN/ccomm.exe" --node planner pub base_theta_sp 0.5 --rate 200 --count 2000 >/dev/null 2>&1 &
  local wp=$!
  local got_w got_l
  got_w=$("${in_w[@]}" "$WBIN/ccomm.exe" --node planner echo wheel0_pos -n 1 --timeout 30 | tr -d '\r')
  got_l=$("${in_l[@]}" "$LBIN/ccomm" --node control echo base_theta_sp -n 1 --timeout 30)
  wait $lp $wp
  local deadline=$((SECONDS + 30)) to_w to_l
  while :; do
    lstats >"$W/lm1.json" && wstats >"$W/wm1.json" || return 1
    to_w=$(counters "$W/lm0.json" "$W/lm1.json" "$W/wm0.json" "$W/wm1.json")
    to_l=$(counters "$W/wm0.json" "$W/wm1.json" "$W/lm0.json" "$W/lm1.json")
    # every write sent (or replaced unsent by the next one: coalesced) and received
    read -r txw rxw lostw badw _ cow <<<"$to_w"; read -r txl rxl lostl badl _ col <<<"$to_l"
    [[ ($badw -eq 0 && $badl -eq 0 && $((txw + cow)) -ge 2000 && $((txl + col)) -ge 2000) || $SECONDS -ge $deadline ]] && break
    sleep 0.5
  done
  say "  multicast: Windows read wheel0_pos '$(echo $got_w | awk '{print $2, $3}')', Linux read base_theta_sp" \
      "'$(echo $got_l | awk '{print $2, $3}')'; Linux -> group -> Windows $txw sent, $rxw received, $lostw lost;" \
      "Windows -> group -> Linux $txl sent, $rxl received, $lostl lost"
  [[ $(echo "$got_w" | awk '{print $2}') == 1.25 && $(echo "$got_l" | awk '{print $2}') == 0.5 &&
     $((txw + cow)) -ge 2000 && $((txl + col)) -ge 2000 && $badw -eq 0 && $badl -eq 0 && $lostw -eq 0 && $lostl -eq 0 ]] ||
    { echo "Linux ccommd:"; tail -5 "$W/linux-ccommd-m.log"; echo "ccommd.exe:"; tail -5 "$W/wine-ccommd-m.log"; return 1; }
}
check "fanout=multicast: Linux and Windows ccommd each read the other's signal through its group, rx == tx, 0 lost" multicast
kill $lpid $wpid 2>/dev/null; wait $lpid $wpid 2>/dev/null
