# SPDX-License-Identifier: Apache-2.0
"""Writes the live-view test signals like a running controller would: tick = 1..COUNT at
RATE Hz (each value once, so a client can tell whether it missed one), wheel_pos and
joint_pos as sines, drive_ok toggling every second, a mode_request event every 25 ticks.
Prints "writer: done N" at the end. Usage: writer.py NODE RATE COUNT"""
import math
import sys
import time

import ccomm


def main() -> int:
    node, rate, count = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
    with ccomm.Client(node) as c:
        tick, wheel, joints = c.signal("tick"), c.signal("wheel_pos"), c.signal("joint_pos")
        drive_ok, mode = c.signal("drive_ok"), c.signal("mode_request")
        start = time.monotonic()
        for i in range(1, count + 1):
            t = i / rate
            wheel.write(math.sin(2 * math.pi * 0.5 * t))
            joints.write([math.sin(t), math.cos(t), 0.5 * math.sin(3 * t)])
            drive_ok.write(int(t) % 2 == 0)
            if i % 25 == 0:
                mode.write(i // 25)
            tick.write(i)
            delay = start + i / rate - time.monotonic()
            if delay > 0:
                time.sleep(delay)
    print("writer: done %d" % count, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
