#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Frame authentication end to end (two boards, raw Ethernet):
#   - a key file others can read is refused at start-up, with what to do;
#   - an authenticated heartbeat built independently in Python (authframe.py, from
#     docs/protocol.md) is accepted; the same frame again is a replay; a flipped tag bit
#     is an auth failure; a correctly tagged frame from an unknown node is refused;
#   - with keys on both sides values flow; frames captured on the wire and sent again
#     (flood --replay) are all refused and counted as replays, and change no value;
#   - a wrong key, or a key on one side only, is refused visibly (counted, peer down).
source "$(dirname "$0")/lib.sh"
require_root
require_build
build_tool flood
build_torture
"$CCOMM_PYTHON" -c 'import hashlib; hashlib.blake2b(b"", key=b"k", digest_size=16)' ||
  skip_all "python3 without keyed BLAKE2b"

KEY=$WORK/auth.key
head -c 32 /dev/urandom >"$KEY"
chmod 600 "$KEY"
with_key() {  # with_key KEYFILE OUT: reliability.xml with auth_key_file=KEYFILE
  sed "s|<network |<network auth_key_file=\"$1\" |" "$CONFIG" >"$2"
}
with_key "$KEY" "$WORK/auth.xml"
HASH=$("$BIN/ccommd" --check "$WORK/auth.xml" | sed -n 's/.*hash \([0-9a-f]*\)).*/\1/p')
delta() { echo $(( $(counter "$1" "$2") - ${3:-0} )); }

make_pair

# 1. Key file permissions.
cp "$KEY" "$WORK/loose.key"; chmod 644 "$WORK/loose.key"
with_key "$WORK/loose.key" "$WORK/loose.xml"
out=$(ip netns exec "$NS_C" "$BIN/ccommd" --node control --no-rt -c "$WORK/loose.xml" 2>&1); rc=$?
note "ccommd with a 0644 key file: exit $rc: $out"
check "a key file readable by others is refused (exit 3, says chmod 600)" \
  [ $rc -eq 3 -a -n "$(echo "$out" | grep 'chmod 600')" ]

# 2. Independently built frames against the planner alone (control not running).
DAEMON_CONFIG=$WORK/auth.xml start_daemon planner || { not_ok "planner starts with a key"; finish; }
send() { in_ns control "$CCOMM_PYTHON" "$REL_DIR/authframe.py" --ifname eth0 --key "$KEY" --hash "$HASH" "$@" >/dev/null; }
settle() { sleep 0.2; stats planner; }
stats planner
rx0=$(counter planner frames_rx); rp0=$(counter planner frames_replayed)
af0=$(counter planner frames_auth_failed); us0=$(counter planner frames_unknown_sender)
T=$("$CCOMM_PYTHON" -c 'import time; print(time.monotonic_ns())')
send --sender 0 --dest 1 --seq 5 --send-ns "$T"; settle
check "a heartbeat tagged by an independent implementation is accepted (frames_rx +$(delta planner frames_rx "$rx0"))" \
  [ "$(delta planner frames_rx "$rx0")" -eq 1 -a "$(peer planner heartbeats_rx)" -ge 1 ]
send --sender 0 --dest 1 --seq 5 --send-ns "$T" --times 3; settle
check "the same frame sent again 3 times: 3 replays ($(delta planner frames_replayed "$rp0"))" \
  [ "$(delta planner frames_replayed "$rp0")" -eq 3 -a "$(delta planner frames_rx "$rx0")" -eq 1 ]
send --sender 0 --dest 1 --seq 6 --send-ns $((T + 1000)) --flip-tag; settle
check "one flipped tag bit: auth failure ($(delta planner frames_auth_failed "$af0"))" \
  [ "$(delta planner frames_auth_failed "$af0")" -eq 1 ]
send --sender 7 --dest 1 --seq 0 --send-ns $((T + 2000)); settle
send --sender 1 --dest 1 --seq 0 --send-ns $((T + 3000)); settle
check "correctly tagged frames from node 7 (not in the file) and from the receiver's own id: unknown sender ($(delta planner frames_unknown_sender "$us0"))" \
  [ "$(delta planner frames_unknown_sender "$us0")" -eq 2 -a "$(delta planner frames_rx "$rx0")" -eq 1 ]

# 3. Both keyed: values flow; recorded frames replayed are refused.
DAEMON_CONFIG=$WORK/auth.xml start_daemon control || { not_ok "control starts with a key"; finish; }
spawn "$WORK/w.log" control "$WORK/torture" -n control write t_state --rate 1000
w=$!
spawn "$WORK/c.log" planner "$WORK/torture" -n planner check t_state
c=$!
wait_for 20 peer_up planner
check "with keys on both sides the peers are up" [ "$(peer planner alive)" = true ]
rp0=$(counter planner frames_replayed); af0=$(counter planner frames_auth_failed); sd0=$(sock_drops planner)
in_ns control "$WORK/flood" --ifname eth0 --replay 300 --times 2 --rate 5000 >"$WORK/replay.json" 2>&1
settle
sd=$(( $(sock_drops planner) - sd0 ))
figure "replayed $(json_get "$WORK/replay.json" sent) frames captured from control's own traffic:" \
       "frames_replayed +$(delta planner frames_replayed "$rp0"), frames_auth_failed +$(delta planner frames_auth_failed "$af0"), dropped at the socket $sd"
check "every recorded frame sent again is refused as a replay (600 == replayed + socket drops)" \
  [ "$(json_get "$WORK/replay.json" sent)" -eq 600 -a $(( $(delta planner frames_replayed "$rp0") + sd )) -eq 600 ]
sleep 0.5
kill -TERM $w $c; wait $w $c
final=$(grep '"final"' "$WORK/c.log")
figure "checker at planner: $final"
check "the values seen at the planner stayed valid and in order through the replays" \
  "$CCOMM_PYTHON" -c 'import json,sys; c=json.loads(sys.argv[1] or "{}")
sys.exit(0 if c.get("values", 0) > 100 and c.get("corrupt") is False and c.get("order_violations") == 0 else 1)' "$final"

# 4. A wrong key on control, then no key at all on control: refused both ways, visibly.
for variant in wrong none; do
  stop_daemon control
  if [[ $variant = wrong ]]; then
    head -c 32 /dev/urandom >"$WORK/other.key"; chmod 600 "$WORK/other.key"
    with_key "$WORK/other.key" "$WORK/control.xml"
  else
    cp "$CONFIG" "$WORK/control.xml"
  fi
  sleep 0.5  # the planner declares control lost
  stats planner; af0=$(counter planner frames_auth_failed); rx0=$(counter planner frames_rx)
  DAEMON_CONFIG=$WORK/control.xml start_daemon control || { not_ok "control starts ($variant key)"; continue; }
  sleep 1
  stats planner; stats control
  check "$variant key on control: the planner refuses its frames (auth_failed +$(delta planner frames_auth_failed "$af0"), rx +$(delta planner frames_rx "$rx0")) and control refuses the planner's ($(counter control frames_auth_failed)); peer down both ways" \
    [ "$(delta planner frames_auth_failed "$af0")" -ge 5 -a "$(delta planner frames_rx "$rx0")" -eq 0 \
      -a "$(counter control frames_auth_failed)" -ge 5 -a "$(peer planner alive)" = false -a "$(peer control alive)" = false ]
done
finish
