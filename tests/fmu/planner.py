# SPDX-License-Identifier: Apache-2.0
"""The other node of the ccomm-fmu test: writes the FMUs' inputs over the network and
keeps every output value that arrives (history tap), for compare.py.

  planner.py write OUT.json STOPFILE   write inputs until STOPFILE exists (at most 120 s),
                                       then store what arrived in OUT.json
Runs on node "planner" (CCOMM_NODE); PYTHONPATH holds the ccomm package, CCOMM_LIBRARY libccomm.
The pattern's clock starts when plant3's first output arrives: a sine force u with one 150 ms gap (u turns stale: the safe value 0
and u_fresh = 0 reach the plant), an array w, k and kp changed once, a stepped setpoint.
"""
import json
import math
import os
import sys
import time

import ccomm

OUTPUTS = ["x", "state", "command", "ticks", "saturated"]


def main() -> int:
    out_path, stop_path = sys.argv[2], sys.argv[3]
    c = ccomm.Client()
    histories = {name: c.signal(name).history(back=0) for name in OUTPUTS}
    kept = {name: [] for name in OUTPUTS}
    print("writing", flush=True)
    start = None
    deadline = time.monotonic() + 120
    n = 0
    while not os.path.exists(stop_path) and time.monotonic() < deadline:
        if start is None and kept["x"]:
            start = time.monotonic()
        t = 0.0 if start is None else time.monotonic() - start
        if not 0.8 <= t < 0.95:  # the gap: u stale for ~100 ms
            c.write("u", 2.0 * math.sin(2 * math.pi * 1.5 * t))
        c.write("w", [0.5 * math.cos(2 * math.pi * 0.7 * t), 0.2 if t > 1.2 else 0.0])
        c.write("k", 40.0 if t < 1.0 else 25.0)
        c.write("setpoint", 0.0 if t < 0.3 else (0.4 if t < 1.6 else -0.2))
        c.write("kp", 2.0 if t < 1.3 else 3.5)
        n += 1
        for name, h in histories.items():  # drain as we go: the ring holds 4096 values
            kept[name].extend(r.value if not hasattr(r.value, "tolist") else r.value.tolist()
                              for r in h.drain())
        time.sleep(0.002)
    time.sleep(0.2)
    for name, h in histories.items():
        kept[name].extend(r.value if not hasattr(r.value, "tolist") else r.value.tolist() for r in h.drain())
        kept[name + ".overrun"] = h.overrun
    kept["writes"] = n
    with open(out_path, "w") as f:
        json.dump(kept, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
