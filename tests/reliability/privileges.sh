#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Least privilege:
#   - ccommd started as root ends up with no capability in any thread, no_new_privs set,
#     and still forwards; its segments have mode 0660;
#   - with <realtime priority mlockall>, its I/O threads run SCHED_FIFO and memory is
#     locked, keeping at most CAP_SYS_NICE / CAP_IPC_LOCK, and only where the resource
#     limits cannot be raised instead;
#   - as an unprivileged user it needs only ambient CAP_NET_RAW for raw Ethernet (and
#     says what to do without it), nothing at all for UDP;
#   - the unit file: systemd-analyze security (offline) score and verify; every system
#     call ccommd makes (strace) is allowed by its SystemCallFilter=@system-service.
#
#   PRIV_MAX_EXPOSURE (default 2.5): highest acceptable systemd-analyze exposure score.
source "$(dirname "$0")/lib.sh"
require_root
require_build
build_torture
MAX_EXPOSURE=${PRIV_MAX_EXPOSURE:-2.5}

# caps NODE|PID: "prm eff bnd amb nnp" of every thread, one line each
caps_of() {
  local t
  for t in /proc/"$1"/task/*; do
    awk '/^CapPrm/{p=$2} /^CapEff/{e=$2} /^CapBnd/{b=$2} /^CapAmb/{a=$2} /^NoNewPrivs/{n=$2}
         END {print p, e, b, a, n}' "$t/status"
  done
}
all_threads() {  # all_threads PID "prm eff bnd amb nnp": every thread has exactly that
  local want=$2 line
  while read -r line; do [[ $line = "$want" ]] || return 1; done < <(caps_of "$1")
}
Z=0000000000000000

make_pair

# 1. As root: everything dropped after start-up, forwarding unaffected.
start_daemon control || { not_ok "ccommd control starts"; finish; }
start_daemon planner || { not_ok "ccommd planner starts"; finish; }
note "control threads (CapPrm CapEff CapBnd CapAmb NoNewPrivs): $(caps_of "${DPID[control]}" | sort -u | tr '\n' ';')"
check "root ccommd: no capability left in any thread, bounding set empty, no_new_privs" \
  all_threads "${DPID[control]}" "$Z $Z $Z $Z 1"
spawn "$WORK/w.log" control "$WORK/torture" -n control write t_state --rate 500
w=$!
sleep 0.5
s1=$(cli planner echo t_state --once | sed -n 's/.* seq=\([0-9]*\).*/\1/p')
s2_moved() { s2=$(cli planner echo t_state --once | sed -n 's/.* seq=\([0-9]*\).*/\1/p'); [ "${s2:-0}" -gt "${s1:-0}" ]; }
sleep 0.3
wait_for 20 s2_moved
kill -TERM $w; wait $w
check "values still flow after the drop (seq $s1 -> $s2)" [ "${s2:-0}" -gt "${s1:-0}" ]
mode=$(stat -c '%a %U:%G' /dev/shm/"$TAG".control)
figure "segment /dev/shm/$TAG.control: mode, owner: $mode (group 'ccomm' when that group exists)"
check "segment mode 0660" [ "${mode%% *}" = 660 ]
stop_daemon control; stop_daemon planner

# 2. Real-time configuration as root.
sed 's|\(<node name="control"[^>]*\)/>|\1><realtime priority="10" mlockall="true"/></node>|' "$CONFIG" >"$WORK/rt.xml"
start_daemon planner
# Without --no-rt (start_daemon passes it), so started by hand.
ip netns exec "$NS_C" "$BIN/ccommd" --node control -c "$WORK/rt.xml" >"$WORK/rt.log" 2>&1 &
DPID[control]=$!; PIDS+=($!)
sleep 1
p=${DPID[control]}
fifo=$(ps -L -o cls=,rtprio= -p "$p" | grep -c 'FF *10')
lck=$(awk '/^VmLck/{print $2}' "/proc/$p/status")
note "$(grep -i capabilities "$WORK/rt.log")"
# What may be kept: only what the limits cannot replace here.
allowed=0
[[ $(ulimit -Hr) != unlimited && $(ulimit -Hr) -lt 10 ]] && allowed=$((allowed | 1 << 23))   # CAP_SYS_NICE
[[ $(ulimit -Hl) != unlimited ]] && allowed=$((allowed | 1 << 14))                            # CAP_IPC_LOCK
eff=$(caps_of "$p" | awk '{print $2}' | sort -u)
figure "realtime: $fifo I/O threads SCHED_FIFO 10, VmLck $lck kB, remaining CapEff $eff (allowed: $(printf '%016x' $allowed))"
check "realtime: both I/O threads SCHED_FIFO 10 and memory locked" [ "$fifo" -eq 2 -a "${lck:-0}" -gt 0 ]
check "realtime: nothing kept beyond CAP_SYS_NICE/CAP_IPC_LOCK where limits cannot stand in" \
  [ "$(echo "$eff" | wc -l)" -eq 1 -a $(( 0x$eff & ~allowed )) -eq 0 ]
stop_daemon control; stop_daemon planner
rm -f /dev/shm/"$TAG".*

# 3. Unprivileged: raw Ethernet with ambient CAP_NET_RAW only; without it a clear error.
USER_=nobody GROUP_=nogroup
getent group nogroup >/dev/null || GROUP_=nobody
as_user() { setpriv --reuid="$USER_" --regid="$GROUP_" --clear-groups "$@"; }
if ! as_user test -r "$CONFIG" -a -x "$BIN/ccommd"; then
  note "skipping the unprivileged runs: $USER_ cannot read $CONFIG or run $BIN/ccommd"
else
  start_daemon control
  ip netns exec "$NS_P" setpriv --reuid="$USER_" --regid="$GROUP_" --clear-groups --inh-caps=+net_raw \
    --ambient-caps=+net_raw "$BIN/ccommd" --node planner --no-rt -c "$CONFIG" >"$WORK/user.log" 2>&1 &
  DPID[planner]=$!; PIDS+=($!)
  wait_for 20 peer_up planner
  check "as $USER_ with only ambient CAP_NET_RAW: raw transport works (peer up)" [ "$(peer planner alive)" = true ]
  # (Without CAP_SETPCAP the bounding set stays; with nothing permitted and no_new_privs
  # it grants nothing.)
  note "$USER_ threads: $(caps_of "${DPID[planner]}" | sort -u | tr '\n' ';')"
  check "as $USER_: no capability left after start-up (permitted, effective, ambient), no_new_privs" \
    [ "$(caps_of "${DPID[planner]}" | awk '{print $1, $2, $4, $5}' | sort -u)" = "$Z $Z $Z 1" ]
  owner=$(stat -c '%a %U' /dev/shm/"$TAG".planner)
  check "as $USER_: its segment is its own, mode 0660 ($owner)" [ "$owner" = "660 $USER_" ]
  stop_daemon planner
  rm -f /dev/shm/"$TAG".planner
  out=$(ip netns exec "$NS_P" setpriv --reuid="$USER_" --regid="$GROUP_" --clear-groups \
        "$BIN/ccommd" --node planner --no-rt -c "$CONFIG" 2>&1); rc=$?
  note "without CAP_NET_RAW: exit $rc: $out"
  check "without CAP_NET_RAW raw Ethernet is refused with what to do (exit 3)" \
    [ $rc -eq 3 -a -n "$(echo "$out" | grep CAP_NET_RAW)" ]
  rm -f /dev/shm/"$TAG".*
  stop_daemon control
  rm -f /dev/shm/"$TAG".*
  for n in control planner; do
    ip netns exec "$(ns_of $n)" setpriv --reuid="$USER_" --regid="$GROUP_" --clear-groups \
      "$BIN/ccommd" --node $n --no-rt --transport udp -c "$CONFIG" >"$WORK/udp-$n.log" 2>&1 &
    DPID[$n]=$!; PIDS+=($!)
  done
  wait_for 20 peer_up planner
  check "as $USER_ without any capability: UDP transport works (peer up)" [ "$(peer planner alive)" = true ]
  stop_daemon control; stop_daemon planner
fi

# 4. The unit file.
sed "s|@CCOMM_BINDIR@|$BIN|" "$ROOT/dist/ccommd.service" >"$WORK/ccommd.service"
if systemd-analyze --help 2>/dev/null | grep -q -- '--offline'; then
  systemd-analyze security --offline=true "$WORK/ccommd.service" >"$WORK/security.txt" 2>&1
  score=$(sed -n 's/.*Overall exposure level for ccommd.service: \([0-9.]*\).*/\1/p' "$WORK/security.txt")
  figure "systemd-analyze security --offline: exposure $score ($(grep -o 'Overall.*' "$WORK/security.txt"))"
  check "unit exposure score <= $MAX_EXPOSURE ($score)" \
    "$CCOMM_PYTHON" -c 'import sys; sys.exit(0 if float(sys.argv[1] or 99) <= float(sys.argv[2]) else 1)' "$score" "$MAX_EXPOSURE"
  check "systemd-analyze verify accepts the unit" systemd-analyze verify --man=no "$WORK/ccommd.service"
else
  note "systemd-analyze without --offline: unit checks skipped"
fi

# 5. System calls: everything ccommd does (start with RT and auth, forward, stop) must be
#    allowed by SystemCallFilter=@system-service.
if command -v strace >/dev/null && command -v systemd-analyze >/dev/null; then
  head -c 32 /dev/urandom >"$WORK/k"; chmod 600 "$WORK/k"
  sed "s|<network |<network auth_key_file=\"$WORK/k\" |" "$WORK/rt.xml" >"$WORK/rt-auth.xml"
  DAEMON_CONFIG=$WORK/rt-auth.xml start_daemon planner
  ip netns exec "$NS_C" strace -f -qq -o "$WORK/strace.txt" "$BIN/ccommd" --node control -c "$WORK/rt-auth.xml" \
    >"$WORK/strace-ccommd.log" 2>&1 &
  st=$!; PIDS+=($st)
  sleep 1.5
  cli control pub ping 1 >/dev/null
  sleep 0.3
  kill -TERM "$(pgrep -P $st)"; wait $st
  stop_daemon planner
  used=$(sed -n 's/^[0-9]* *\(<... \)\{0,1\}\([a-z0-9_]*\)[( ].*/\2/p' "$WORK/strace.txt" | grep -v '^$' | sort -u)
  denied=$("$CCOMM_PYTHON" - "$used" <<'EOF'
import subprocess, sys
groups, cur = {}, None
for line in subprocess.run(["systemd-analyze", "syscall-filter"], capture_output=True, text=True).stdout.splitlines():
    if line.startswith("@"):
        cur = groups.setdefault(line.split()[0], set())
    elif cur is not None and line.strip() and not line.strip().startswith("#"):
        cur.add(line.strip())
def expand(name, seen=()):
    out = set()
    for s in groups.get(name, ()):
        out |= expand(s, seen + (name,)) if s.startswith("@") and s not in seen else {s}
    return out
allowed = expand("@system-service")
print(" ".join(s for s in sys.argv[1].split() if s not in allowed and s not in ("exit", "resumed")))
EOF
)
  figure "system calls made by ccommd: $(echo "$used" | wc -l); outside @system-service: ${denied:-none}"
  check "every system call ccommd makes is in @system-service (${denied:-none})" [ -z "$denied" ]
else
  note "strace not installed: system call check skipped"
fi
finish
