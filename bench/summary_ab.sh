#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Do node summaries (ccomm stats --all) disturb control traffic? A/B, interleaved:
# two ccommd on loopback UDP in a private network namespace, ccomm-latency ping -> echo
# at 1 kHz, once with summary_ms="0" (none) and once with summary_ms="100" (the most
# they may send: one frame per 100 ms per destination), ROUNDS times each. Prints each
# run's JSON line and the medians of p50/p99 per setting (docs/performance.md, 10.).
#   bench/summary_ab.sh BUILD_DIR [ROUNDS] [SECONDS]      (root: network namespaces)
set -uo pipefail
build=${1:?usage: bench/summary_ab.sh BUILD_DIR [ROUNDS] [SECONDS]}
rounds=${2:-6} secs=${3:-3}
bin=$build/bin
. "$(dirname "$0")/../scripts/python.sh"  # Debian's Python, not PATH's (docs/testing.md, "Which Python")
[ "$(id -u)" -eq 0 ] || { echo "summary_ab: needs root (network namespaces)" >&2; exit 4; }
work=$(mktemp -d "${TMPDIR:-/tmp}/ccomm-summary-ab-XXXXXX")
ns=ccsab$$
cleanup() { ip netns del "$ns" 2>/dev/null; rm -f /dev/shm/"$ns"*; rm -rf "$work"; }
trap cleanup EXIT
results=$work/results.jsonl
for round in $(seq "$rounds"); do
  for sm in 0 100; do
    ip netns add "$ns" && ip netns exec "$ns" ip link set lo up || exit 1
    export CCOMM_SHM_PREFIX=/$ns.$sm.
    cat >"$work/ab.xml" <<XML
<?xml version="1.0" encoding="UTF-8"?>
<ccomm version="1">
  <network udp_port="47874" summary_ms="$sm"/>
  <node name="a" ip="127.0.0.1" transport="udp"/>
  <node name="b" ip="127.0.0.2" transport="udp"/>
  <signal name="ping" type="double" producer="a" consumers="b"/>
  <signal name="pong" type="double" producer="b" consumers="a"/>
</ccomm>
XML
    ip netns exec "$ns" "$bin/ccommd" -c "$work/ab.xml" -n a --no-rt >/dev/null 2>&1 & pa=$!
    ip netns exec "$ns" "$bin/ccommd" -c "$work/ab.xml" -n b --no-rt >/dev/null 2>&1 & pb=$!
    sleep 0.5
    ip netns exec "$ns" "$bin/ccomm-latency" -n b -m echo -d $((secs + 2)) >/dev/null 2>&1 & pe=$!
    sleep 0.2
    ip netns exec "$ns" "$bin/ccomm-latency" -n a -m ping -r 1000 -d "$secs" --label "summary_ms=$sm" | tee -a "$results"
    kill $pe $pa $pb 2>/dev/null; wait $pe $pa $pb 2>/dev/null
    ip netns del "$ns"; rm -f /dev/shm/"$ns".$sm.*
  done
done
"$CCOMM_PYTHON" - "$results" <<'PY'
import json, statistics, sys
runs = {}
for line in open(sys.argv[1]):
    d = json.loads(line)
    runs.setdefault(d["label"], []).append(d)
for label, ds in sorted(runs.items()):
    print("# %s: %d runs, median p50 %.1f us, median p99 %.1f us, lost %d of %d" % (
        label, len(ds), statistics.median(x["p50_ns"] for x in ds) / 1e3,
        statistics.median(x["p99_ns"] for x in ds) / 1e3, sum(x["lost"] for x in ds), sum(x["sent"] for x in ds)))
PY
