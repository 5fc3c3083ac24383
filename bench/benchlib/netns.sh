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
PAIR=$(cd "$(dirname "$0")/../.." && pwd)/scripts/netns-pair

need_root() {
    if [ "$(id -u)" -ne 0 ]; then
        echo "netns.sh: needs root to create network namespaces; skipping" >&2
        exit 4
    fi
    command -v ip >/dev/null 2>&1 || { echo "netns.sh: iproute2 'ip' not found; skipping" >&2; exit 4; }
}


down() { "$PAIR" down "$NS_A" "$NS_B"; }

up() {
    # The one two-board network of tests, bench and demo (scripts/netns-pair), with the
    # bench's addresses and multicast routed over eth0 (LCM's udpm).
    rc=0
    "$PAIR" up "$NS_A" "$NS_B" --ip-a "$IP_A/24" --ip-b "$IP_B/24" --mac-a "$MAC_A" --mac-b "$MAC_B" \
        --multicast || rc=$?
    [ $rc -eq 0 ] && CREATED=1
    [ $rc -eq 4 ] && exit 4
    return $rc
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
