#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
#
# Two network namespaces joined by one veth pair, for the network floor and peer
# measurements (scripts/bench-floors uses `up`/`down`; `floor` is the stand-alone
# way to run net_floor between them).
#
#   netns.sh up                 create ${CCB_PREFIX:-ccb}-a and -b, each with eth0
#   netns.sh down               delete both (and with them the veth pair)
#   netns.sh status             show what exists
#   netns.sh floor NET_FLOOR raw|udp [ping options...]
#                               up, echo in -b, ping in -a, print the JSON line,
#                               tear down on any exit (trap)
#
# Inside: ns -a eth0 198.18.76.1/24 02:cc:b0:00:00:01, ns -b eth0 198.18.76.2/24
# 02:cc:b0:00:00:02 (198.18.0.0/15 is the RFC 2544 benchmarking range, so it cannot
# clash with a real network), multicast routed over eth0 (LCM's udpm), IPv6 off so
# no router/neighbour chatter lands in the measurement.
# Needs root (CAP_SYS_ADMIN and CAP_NET_ADMIN); exits 4 ("skipped") without it.
set -eu

P=${CCB_PREFIX:-ccb}
CREATED=0 # set once this invocation made a namespace: only then may a failure remove them
NS_A=$P-a
NS_B=$P-b
IP_A=198.18.76.1
IP_B=198.18.76.2
MAC_A=02:cc:b0:00:00:01
MAC_B=02:cc:b0:00:00:02

need_root() {
    if [ "$(id -u)" -ne 0 ]; then
        echo "netns.sh: needs root to create network namespaces; skipping" >&2
        exit 4
    fi
    command -v ip >/dev/null 2>&1 || { echo "netns.sh: iproute2 'ip' not found; skipping" >&2; exit 4; }
}

exists() { ip netns list 2>/dev/null | awk '{print $1}' | grep -qx "$1"; }

down() {
    for ns in "$NS_A" "$NS_B"; do
        if exists "$ns"; then
            # Anything still running inside would keep the namespace alive: end it.
            for pid in $(ip netns pids "$ns" 2>/dev/null); do kill "$pid" 2>/dev/null || true; done
            ip netns del "$ns" 2>/dev/null || true
        fi
    done
}

up() {
    for ns in "$NS_A" "$NS_B"; do
        if exists "$ns"; then
            echo "netns.sh: namespace $ns already exists (another run, or a stale one: 'netns.sh down')" >&2
            exit 1
        fi
    done
    if ! ip netns add "$NS_A" 2>/dev/null; then
        echo "netns.sh: cannot create network namespaces here (no CAP_SYS_ADMIN?); skipping" >&2
        exit 4
    fi
    CREATED=1
    ip netns add "$NS_B"
    # Create the pair directly inside the namespaces: no name is ever taken in the
    # host namespace, so parallel runs with other prefixes cannot collide.
    ip link add eth0 netns "$NS_A" address "$MAC_A" type veth peer name eth0 netns "$NS_B" address "$MAC_B"
    for side in a b; do
        if [ $side = a ]; then ns=$NS_A addr=$IP_A; else ns=$NS_B addr=$IP_B; fi
        ip netns exec "$ns" sysctl -qw net.ipv6.conf.all.disable_ipv6=1 net.ipv6.conf.default.disable_ipv6=1 \
            >/dev/null 2>&1 || true
        ip -n "$ns" link set lo up
        ip -n "$ns" addr add "$addr/24" dev eth0
        ip -n "$ns" link set eth0 up
        ip -n "$ns" route add 224.0.0.0/4 dev eth0
    done
    # Wait for the carrier (both ends up) so the first frames are not dropped.
    i=0
    while [ $i -lt 50 ]; do
        if ip -n "$NS_A" link show eth0 | grep -q 'state UP' && ip -n "$NS_B" link show eth0 | grep -q 'state UP'; then
            return 0
        fi
        i=$((i + 1))
        sleep 0.1
    done
    echo "netns.sh: veth did not come up" >&2
    return 1
}

floor() {
    [ $# -ge 2 ] || { echo "usage: netns.sh floor NET_FLOOR raw|udp [ping options...]" >&2; exit 2; }
    bin=$1 transport=$2
    shift 2
    [ -x "$bin" ] || { echo "netns.sh: $bin is not executable" >&2; exit 2; }
    trap '[ "$CREATED" = 1 ] && down' EXIT
    trap 'exit 130' INT TERM
    up
    if [ "$transport" = raw ]; then
        ip netns exec "$NS_B" "$bin" --transport raw --role echo --if eth0 --idle-ms 30000 &
        ip netns exec "$NS_A" "$bin" --transport raw --role ping --if eth0 --dst "$MAC_B" "$@"
    else
        ip netns exec "$NS_B" "$bin" --transport udp --role echo --bind "$IP_B:47900" --idle-ms 30000 &
        ip netns exec "$NS_A" "$bin" --transport udp --role ping --peer "$IP_B:47900" "$@"
    fi
    rc=$?
    wait || true
    return $rc
}

cmd=${1:-}
[ $# -gt 0 ] && shift
case "$cmd" in
up)
    need_root
    # A half-made pair is removed again; a complete one stays for the caller.
    trap 'rc=$?; [ $rc -ne 0 ] && [ "$CREATED" = 1 ] && down; exit $rc' EXIT
    trap 'exit 130' INT TERM
    up
    ;;
down) need_root; down ;;
status) ip netns list | grep -E "^($NS_A|$NS_B)( |$)" || echo "no $P namespaces" ;;
floor) need_root; floor "$@" ;;
*)
    sed -n '4,18p' "$0" >&2
    exit 2
    ;;
esac
