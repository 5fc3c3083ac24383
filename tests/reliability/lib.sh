# SPDX-License-Identifier: Apache-2.0
# Shared helpers of the reliability tests (sourced). Network namespaces named
# rel<pid>-<x>, daemons and helpers started here are tracked by pid and removed on exit.
#
# Environment:
#   CCOMM_BUILD_DIR   build with bin/ccommd, bin/ccomm, lib/libccomm.so (default build/release, what scripts/build makes)
#   REL_KEEP_LOGS=1   keep the work directory (logs) after the test
set -uo pipefail

REL_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
ROOT=$(cd "$REL_DIR/../.." && pwd)
. "$ROOT/scripts/python.sh"  # Debian's Python, not PATH's (docs/testing.md, "Which Python")
BUILD=${CCOMM_BUILD_DIR:-$ROOT/build/release}
[[ $BUILD = /* ]] || BUILD=$ROOT/$BUILD
BIN=$BUILD/bin
CONFIG=$REL_DIR/reliability.xml
TAG=rel$$
export CCOMM_SHM_PREFIX=/$TAG.
WORK=$(mktemp -d "${TMPDIR:-/tmp}/ccomm-$TAG-XXXXXX")
TESTNUM=0
FAILED=0
PIDS=()
NAMESPACES=()

# ---- TAP-ish output ------------------------------------------------------------------
ok() { TESTNUM=$((TESTNUM + 1)); echo "ok $TESTNUM - $*"; }
not_ok() { TESTNUM=$((TESTNUM + 1)); FAILED=$((FAILED + 1)); echo "not ok $TESTNUM - $*"; }
check() {  # check "description" command...: ok if the command succeeds
  local d=$1; shift
  if "$@"; then ok "$d"; else not_ok "$d"; fi
}
figure() { echo "# figure: $*"; }
note() { echo "# $*"; }
skip_all() { echo "1..0 # SKIP $*"; exit 4; }
finish() {
  echo "1..$TESTNUM"
  [[ $FAILED -eq 0 ]] && exit 0
  echo "# $FAILED of $TESTNUM failed; logs in $WORK" >&2
  REL_KEEP_LOGS=1
  exit 1
}

require_root() {
  [[ $(id -u) -eq 0 ]] || skip_all "needs root (network namespaces, raw sockets)"
  command -v ip >/dev/null || skip_all "needs iproute2"
}
require_build() {
  for b in ccommd ccomm; do
    [[ -x $BIN/$b ]] || { echo "Bail out! $BIN/$b missing: build first or set CCOMM_BUILD_DIR"; exit 1; }
  done
}

# ---- helpers compiled from tests/reliability/*.c ----------------------------------------
build_tool() {  # build_tool NAME [extra cc args]: compiles NAME.c into $WORK/NAME
  local name=$1; shift
  cc -O2 -Wall -Wextra -Werror -o "$WORK/$name" "$REL_DIR/$name.c" "$@" ||
    { echo "Bail out! cannot compile $name.c"; exit 1; }
}
build_torture() {
  build_tool torture -I"$ROOT/src/include" -L"$BUILD/lib" -lccomm -Wl,-rpath,"$BUILD/lib"
}

# ---- cleanup -----------------------------------------------------------------------
cleanup() {
  local p
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; done
  for p in "${PIDS[@]}"; do wait "$p" 2>/dev/null; done
  local ns
  for ns in "${NAMESPACES[@]}"; do ip netns del "$ns" 2>/dev/null; done
  rm -f /dev/shm/"$TAG".* 2>/dev/null
  if [[ ${REL_KEEP_LOGS:-0} = 1 ]]; then echo "# logs kept in $WORK" >&2; else rm -rf "$WORK"; fi
}
trap cleanup EXIT
trap 'exit 1' INT TERM

# Leftovers of an earlier run that was killed outright (SIGKILL: no cleanup ran): its
# namespaces and segments carry its pid (rel<pid>-*); remove those whose run is gone.
sweep_stale() {
  local ns pid
  for ns in $(ip netns list 2>/dev/null | awk '{print $1}' | grep -E '^rel[0-9]+-[a-z]+$'); do
    pid=${ns#rel}; pid=${pid%%-*}
    [[ -d /proc/$pid ]] && continue
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -9 2>/dev/null
    ip netns del "$ns" 2>/dev/null
  done
  for f in /dev/shm/rel[0-9]*.*; do
    [[ -e $f ]] || continue
    pid=${f#/dev/shm/rel}; pid=${pid%%.*}
    [[ $pid =~ ^[0-9]+$ && ! -d /proc/$pid ]] && rm -f "$f"
  done
}
sweep_stale

# spawn LOGFILE NODE command...: runs command in NODE's namespace in the background.
# `ip netns exec` execs the command, so $! (also kept in PIDS) is the command itself and
# a signal to it reaches the program, not a wrapper shell.
spawn() {
  local log=$1
  ns_cmd "$2"
  "${NS_CMD[@]}" "${@:3}" >"$log" 2>&1 &
  PIDS+=($!)
}

# wait_for SECONDS COMMAND...: true as soon as COMMAND succeeds (polled every 0.1 s),
# false after SECONDS. For "it happens eventually" checks on a slow, loaded machine.
wait_for() {
  local limit=$1 start=$SECONDS
  shift
  until "$@"; do
    [ $((SECONDS - start)) -ge "$limit" ] && return 1
    sleep 0.1
  done
}

# ---- namespaces ---------------------------------------------------------------------
ns_new() {  # ns_new NAME: a namespace with lo up and IPv6 off (no stray ND/MLD frames)
  ip netns add "$1" || { echo "Bail out! ip netns add $1"; exit 1; }
  NAMESPACES+=("$1")
  ip -n "$1" link set lo up
  ip netns exec "$1" sysctl -qw net.ipv6.conf.all.disable_ipv6=1 net.ipv6.conf.default.disable_ipv6=1
}
ns_up_eth0() {  # ns_up_eth0 NS IP
  ip -n "$1" addr add "$2/24" dev eth0
  ip netns exec "$1" sysctl -qw net.ipv6.conf.eth0.disable_ipv6=1
  ip -n "$1" link set eth0 up
}
# control (NS_C, 10.42.0.1) and planner (NS_P, 10.42.0.2) joined by one veth pair.
make_pair() {
  NS_C=$TAG-c NS_P=$TAG-p
  # The one two-board network of tests, bench and demo; removed with the others at exit.
  "$ROOT/scripts/netns-pair" up "$NS_C" "$NS_P" --ip-a 10.42.0.1/24 --ip-b 10.42.0.2/24 ||
    { echo "Bail out! scripts/netns-pair up $NS_C $NS_P"; exit 1; }
  NAMESPACES+=("$NS_C" "$NS_P")
  static_neighbours
}
# Same, with a middle namespace NS_M bridging them through $WORK/impair (m0 <-> m1).
make_impaired_pair() {
  NS_C=$TAG-c NS_P=$TAG-p NS_M=$TAG-m
  ns_new "$NS_C"
  ns_new "$NS_P"
  ns_new "$NS_M"
  ip link add eth0 netns "$NS_C" type veth peer name m0 netns "$NS_M"
  ip link add eth0 netns "$NS_P" type veth peer name m1 netns "$NS_M"
  ns_up_eth0 "$NS_C" 10.42.0.1
  ns_up_eth0 "$NS_P" 10.42.0.2
  ip -n "$NS_M" link set m0 up
  ip -n "$NS_M" link set m1 up
  static_neighbours
}
# Permanent neighbour entries: no ARP frames, so an interface's rx counter holds only
# ccomm traffic (UDP included) and the counts can be compared exactly.
static_neighbours() {
  local mac_c mac_p
  mac_c=$(ip netns exec "$NS_C" cat /sys/class/net/eth0/address)
  mac_p=$(ip netns exec "$NS_P" cat /sys/class/net/eth0/address)
  ip -n "$NS_C" neigh replace 10.42.0.2 lladdr "$mac_p" dev eth0 nud permanent
  ip -n "$NS_P" neigh replace 10.42.0.1 lladdr "$mac_c" dev eth0 nud permanent
}
ns_of() { [[ $1 = control ]] && echo "$NS_C" || echo "$NS_P"; }
# ns_cmd NODE: NS_CMD=(the prefix that runs a program in NODE's network namespace and,
# when the suite gives the node a clock of its own, NODE_MONO_SHIFT_S[NODE]=SECONDS, in a
# time namespace whose CLOCK_MONOTONIC is that far ahead: a board whose monotonic clock is
# not this host's). Both `ip netns exec` and `unshare` exec the program: in the
# background, $! is the program itself.
declare -A NODE_MONO_SHIFT_S
ns_cmd() {
  NS_CMD=(ip netns exec "$(ns_of "$1")")
  [[ -n ${NODE_MONO_SHIFT_S[$1]:-} ]] && NS_CMD+=(unshare --time --monotonic "${NODE_MONO_SHIFT_S[$1]}")
  return 0
}
ns_exec() { local node=$1; shift; ns_cmd "$node"; "${NS_CMD[@]}" "$@"; }  # ns_exec NODE COMMAND...

# ---- daemons and clients ------------------------------------------------------------------
declare -A DPID
start_daemon() {  # start_daemon NODE [extra ccommd args]: waits until its segment is ready
  local node=$1; shift
  local log=$WORK/ccommd-$node.log
  ns_cmd "$node"
  "${NS_CMD[@]}" "$BIN/ccommd" --node "$node" --no-rt -c "${DAEMON_CONFIG:-$CONFIG}" "$@" \
    >>"$log" 2>&1 &
  DPID[$node]=$!
  PIDS+=($!)
  local i
  for i in $(seq 100); do
    if cli "$node" stats --json 2>/dev/null | grep -q '"daemon_alive":true'; then return 0; fi
    kill -0 "${DPID[$node]}" 2>/dev/null || { echo "# ccommd $node exited:"; sed 's/^/#   /' "$log"; return 1; }
    sleep 0.05
  done
  echo "# ccommd $node not ready after 5 s"
  return 1
}
stop_daemon() {  # SIGTERM, wait; returns ccommd's exit status
  local p=${DPID[$1]}
  kill -TERM "$p" 2>/dev/null
  wait "$p" 2>/dev/null
}
daemon_alive() { kill -0 "${DPID[$1]}" 2>/dev/null; }
cli() { local node=$1; shift; ns_exec "$node" "$BIN/ccomm" --node "$node" "$@"; }
in_ns() { ns_exec "$@"; }

# stats NODE: ccomm stats --json into $WORK/stats-NODE.json; jq-free accessors below.
# (--watch prints its first snapshot after 5 ms; a one-shot stats waits 200 ms for rates.)
stats() { stats_json "$1" >"$WORK/stats-$1.json"; }
stats_json() { cli "$1" stats --json --watch 0.005 | head -n1; }
# counter NODE NAME: a daemon counter from the last stats NODE
counter() {
  "$CCOMM_PYTHON" -c 'import json,sys; print(json.load(open(sys.argv[1]))["counters"][sys.argv[2]])' \
    "$WORK/stats-$1.json" "$2"
}
# peer NODE FIELD: a field of the (only) peer of NODE from the last stats NODE
peer() {
  "$CCOMM_PYTHON" -c 'import json,sys; p=json.load(open(sys.argv[1]))["peers"][0]; v=p[sys.argv[2]]
print(str(v).lower() if isinstance(v,bool) else v)' "$WORK/stats-$1.json" "$2"
}
# peer_up NODE: its stats (saved to stats-NODE.json) say the peer is alive. With wait_for:
# "the peers come up" on a loaded machine without guessing how long that takes.
peer_up() { stats "$1" && [ "$(peer "$1" alive)" = true ]; }
# rss PID: "VmRSS VmHWM" in kB
rss() { awk '/^VmRSS/{r=$2} /^VmHWM/{h=$2} END{print r, h}' "/proc/$1/status"; }
# sock_drops NODE: packets dropped at ccommd's socket(s) (receive buffer full), from ss
sock_drops() {
  local pid=${DPID[$1]}
  in_ns "$1" ss -a -n -p -m -0 -u 2>/dev/null | awk -v p="pid=$pid," '
    index($0, p) {want=1} want && /skmem/ {match($0, /,d[0-9]+\)/); s+=substr($0, RSTART+2, RLENGTH-3); want=0}
    END {print s+0}'
}
rx_packets() { in_ns "$1" cat "/sys/class/net/${2:-eth0}/statistics/rx_packets"; }
tx_dropped() { in_ns "$1" cat "/sys/class/net/${2:-eth0}/statistics/tx_dropped"; }
# frames_total NODE: every frame ccommd looked at ends in exactly one of these counters.
frames_total() {
  "$CCOMM_PYTHON" -c 'import json,sys; c=json.load(open(sys.argv[1]))["counters"]
print(sum(c[k] for k in ("frames_rx","frames_bad","frames_wrong_hash","frames_unknown_sender",
                         "frames_auth_failed","frames_replayed","frames_not_for_us")))' "$WORK/stats-$1.json"
}
# snapshot NODE: stats NODE plus SNAP_RX (eth0 rx_packets) and SNAP_DROPS (socket drops),
# taken while no frame arrives (rx_packets equal before and after), so that they agree.
snapshot() {
  local i a b
  for i in $(seq 40); do
    a=$(rx_packets "$1"); stats "$1"; SNAP_DROPS=$(sock_drops "$1"); b=$(rx_packets "$1")
    [[ $a = "$b" ]] && { SNAP_RX=$a; return 0; }
  done
  SNAP_RX=$b
  echo "# snapshot of $1 not quiescent after 40 tries"
  return 1
}
json_get() {  # json_get FILE KEY: a top-level field of the last JSON line of FILE
  "$CCOMM_PYTHON" -c 'import json,sys; print(json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])[sys.argv[2]])' "$1" "$2"
}

# The impairment tool (impair.c, built by build_tool impair) between NS_C and NS_P in NS_M,
# driven through a FIFO: imp_start SEED, then imp COMMAND (prints the JSON line it answers).
imp_start() {
  mkfifo "$WORK/imp.in"
  ip netns exec "$NS_M" "$WORK/impair" --a m0 --b m1 --seed "$1" <"$WORK/imp.in" >"$WORK/imp.out" 2>"$WORK/imp.err" &
  PIDS+=($!)
  exec 7>"$WORK/imp.in"
  local i
  for i in $(seq 100); do grep -q ready "$WORK/imp.out" && return 0; sleep 0.05; done
  echo "Bail out! impair did not start: $(cat "$WORK/imp.err")"
  exit 1
}
imp() {  # imp COMMAND: sends it, waits for the JSON line it prints, echoes that line
  local n i
  n=$(wc -l <"$WORK/imp.out")
  echo "$*" >&7
  for i in $(seq 200); do
    (( $(wc -l <"$WORK/imp.out") > n )) && { tail -n1 "$WORK/imp.out"; return 0; }
    sleep 0.01
  done
  echo "# impair did not answer '$*'" >&2
  return 1
}
