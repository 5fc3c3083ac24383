# SPDX-License-Identifier: Apache-2.0
"""Run inside the clean Debian root by tests/packages/run, once with the python3-ccomm
package and once in a venv with the wheel: the installed ccomm talks to the installed
ccommd (node 'robot' of examples/local-only.xml) after the C programs ran.

    python3 talk.py --version V --library-under DIR [--library-under DIR2] --base B
Exit 0 if every check held; 1 with the failed check on stderr."""
from __future__ import annotations

import argparse
import asyncio
import importlib.metadata
import sys
import threading
import time

import ccomm


def check(what: str, ok: bool, detail: object = "") -> None:
    if not ok:
        print(f"talk: FAILED: {what} {detail}", file=sys.stderr)
        sys.exit(1)
    print(f"talk: ok: {what}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--version", required=True, help="expected package version")
    ap.add_argument("--library-under", required=True, action="append",
                    help="libccomm must be loaded from below this directory (repeatable)")
    ap.add_argument("--base", type=float, required=True, help="joint_pos[0] the C writer wrote")
    ap.add_argument("--daemon-stopped", action="store_true",
                    help="ccommd was stopped: a write must raise DaemonNotRunningError")
    a = ap.parse_args()
    if a.daemon_stopped:
        with ccomm.Client("robot") as c:  # the segment outlives ccommd
            check("ccommd reported down", not c.daemon_alive)
            try:
                c.write("drive_ok", False)
                check("a write while ccommd is down raises DaemonNotRunningError", False)
            except ccomm.DaemonNotRunningError as e:
                check(f"a write while ccommd is down says so: {e}", True)
        return

    check("__version__", ccomm.__version__ == a.version == importlib.metadata.version("ccomm"),
          (ccomm.__version__, importlib.metadata.version("ccomm")))
    lib = ccomm.library_path()
    check(f"libccomm from {lib}", lib.startswith(tuple(a.library_under)), f"(expected under {a.library_under})")

    with ccomm.Client("robot") as c:
        check("ccommd alive", c.daemon_alive)
        pos = c.read("joint_pos")
        want = [a.base + i for i in range(6)]
        check("joint_pos from the find_package(ccomm) program", pos.fresh and list(pos.value) == want,  # type: ignore[arg-type]
              pos)
        check("drive_ok from the pkg-config program", c.read("drive_ok").value is True)

        # Waiting for one signal: a write of another signal must not end the wait.
        vel = c.signal("joint_vel")

        def writer() -> None:
            with ccomm.Client("robot") as w:
                time.sleep(0.1)
                w.write("joint_torque_sp", 0.0)
                time.sleep(0.2)
                w.write("joint_vel", [1, 2, 3, 4, 5, 6])
                for v in (7, 8, 9):
                    w.write("mode_request", v)

        mode = c.signal("mode_request")
        t = threading.Thread(target=writer)
        t0 = time.monotonic()
        t.start()
        r = vel.wait(timeout=5.0)
        dt = time.monotonic() - t0
        check("Signal.wait() for joint_vel", r is not None and list(r.value) == [1, 2, 3, 4, 5, 6]  # type: ignore[arg-type]
              and dt > 0.25, (r, dt))
        t.join()
        events = [e.value for e in mode.events(timeout=0.5)]
        check("events() of mode_request", events == [7, 8, 9], events)

        async def waiting() -> "ccomm.Reading | None":
            th = threading.Timer(0.1, lambda: ccomm.Client("robot").write("joint_vel", 0.5))
            th.start()
            got = await vel.wait_async(timeout=5.0)
            th.join()
            return got

        r = asyncio.run(waiting())
        check("asyncio wait_async()", r is not None and list(r.value) == [0.5] * 6, r)  # type: ignore[arg-type]


if __name__ == "__main__":
    main()
