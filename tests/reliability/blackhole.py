#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Times a black hole for netem.sh: tells tests/reliability/impair.c (through its command
FIFO) to drop everything, and watches `ccomm stats --json --watch 0.005` on the receiving
node until ccommd declares the peer lost and marks SIGNAL stale; then restores the link
and times the peer's return. Prints one JSON line (times in ms)."""
import argparse
import json
import os
import subprocess
import sys
import threading
import time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fifo", required=True)
    ap.add_argument("--ns", required=True)
    ap.add_argument("--ccomm", required=True)
    ap.add_argument("--node", required=True)
    ap.add_argument("--signal", required=True)
    ap.add_argument("--hold", type=float, default=0.6, help="seconds the link stays down")
    a = ap.parse_args()
    watch = subprocess.Popen(["ip", "netns", "exec", a.ns, a.ccomm, "--node", a.node, "stats", "--json",
                              "--watch", "0.005"], stdout=subprocess.PIPE, text=True)
    fifo = os.open(a.fifo, os.O_WRONLY)
    seen = []  # (arrival time, stats) of every line, read by a thread so none is stale
    lock = threading.Lock()

    def reader():
        for line in watch.stdout:
            t = time.monotonic()
            with lock:
                seen.append((t, json.loads(line)))

    threading.Thread(target=reader, daemon=True).start()

    def wait_for(pred, since, timeout=5.0):
        """Arrival time of the first line after `since` for which pred holds, or None."""
        i = 0
        while time.monotonic() < since + timeout:
            with lock:
                batch = seen[i:]
            i += len(batch)
            for t, d in batch:
                if t >= since and pred(d):
                    return t
            time.sleep(0.002)
        return None

    def sig(d):
        return next(s for s in d["signals"] if s["name"] == a.signal)

    try:
        start = time.monotonic()
        if wait_for(lambda d: d["peers"][0]["alive"] and not sig(d)["stale"], start) is None:
            print(json.dumps({"error": "peer not alive / signal not fresh before the black hole"}))
            return 1
        with lock:
            stale0 = sig(seen[-1][1])["stale_transitions"]
        os.write(fifo, b"set loss=100\n")
        t0 = time.monotonic()
        result = {}
        t = wait_for(lambda d: sig(d)["stale_transitions"] > stale0, t0)
        result["stale_ms"] = round((t - t0) * 1000, 1) if t else -1
        t = wait_for(lambda d: not d["peers"][0]["alive"], t0)
        result["down_ms"] = round((t - t0) * 1000, 1) if t else -1
        time.sleep(max(0.0, a.hold - (time.monotonic() - t0)))
        os.write(fifo, b"set loss=0\n")
        t1 = time.monotonic()
        t = wait_for(lambda d: d["peers"][0]["alive"], t1)
        result["up_ms"] = round((t - t1) * 1000, 1) if t else -1
        print(json.dumps(result))
        return 0
    finally:
        os.close(fifo)
        watch.kill()
        watch.wait()

if __name__ == "__main__":
    sys.exit(main())
