# SPDX-License-Identifier: Apache-2.0
"""The floor for ccomm-web's latency: a plain libccomm reader (ccomm.Client.wait + read)
of the same signal in the same run. Prints one JSON line: {"n", "p50_ms", "p99_ms"} of
(receipt - source_time_ns) for each new tick value and "cpu" (CPU seconds per second), until tick reaches COUNT or
TIMEOUT seconds pass. Usage: floor_reader.py NODE COUNT TIMEOUT"""
import json
import sys
import time

import ccomm


def main() -> int:
    node, count, timeout = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    lat_ms = []
    with ccomm.Client(node) as c:
        tick = c.signal("tick")
        last_seq = tick.read().seq
        cpu0, wall0 = time.process_time(), time.monotonic()
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            c.wait(timeout=0.1)
            r = tick.read()
            if r.seq != last_seq:
                lat_ms.append((ccomm.Client.now() - r.source_time_ns) / 1e6)
                last_seq = r.seq
                if r.value == count:
                    break
        cpu_share = (time.process_time() - cpu0) / (time.monotonic() - wall0)
    lat_ms.sort()
    q = lambda p: round(lat_ms[min(len(lat_ms) - 1, int(p * len(lat_ms)))], 3) if lat_ms else None  # noqa: E731
    print(json.dumps({"n": len(lat_ms), "p50_ms": q(0.5), "p99_ms": q(0.99), "cpu": round(cpu_share, 4)}),
          flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
