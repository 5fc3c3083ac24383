# SPDX-License-Identifier: Apache-2.0
"""Waiting for one signal, event iterators and callbacks, asyncio, the version, and a
write while ccommd is down, against a real ccommd (see conftest.py)."""
from __future__ import annotations

import asyncio
import importlib.metadata
import os
import re
import signal
import subprocess
import threading
import time
from pathlib import Path
from typing import Callable, List, Tuple

import pytest

import ccomm
from ccomm import Client, Reading, Signal, Status

REPO = Path(__file__).resolve().parent.parent.parent


def later(delay: float, fn: Callable[[], None]) -> threading.Thread:
    def run() -> None:
        time.sleep(delay)
        fn()

    t = threading.Thread(target=run)
    t.start()
    return t


def write_from_other_client(node: str, *writes: Tuple[str, object]) -> Callable[[], None]:
    def run() -> None:
        with Client(node) as w:
            for name, value in writes:
                w.write(name, value)  # type: ignore[arg-type]
    return run


def drain(sig: Signal) -> None:
    while sig.read().status != Status.EMPTY:
        pass


def test_signal_wait_ignores_other_signals(client: Client, node: str) -> None:
    d = client.signal("d")
    t_other = later(0.1, write_from_other_client(node, ("f", 1.5)))
    t_mine = later(0.5, write_from_other_client(node, ("d", 8.25)))
    t0 = time.monotonic()
    r = d.wait(timeout=5.0)
    dt = time.monotonic() - t0
    t_other.join()
    t_mine.join()
    assert r is not None and r.value == 8.25 and r.status == Status.FRESH
    assert 0.4 < dt < 3.0, f"woke after {dt:.3f} s: the write of 'f' at 0.1 s must not end the wait"
    assert d.wait(timeout=0) is None  # that value was handed out once


def test_signal_wait_sees_a_write_before_the_call_and_times_out(client: Client, node: str) -> None:
    d = client.signal("d")
    d.read()
    write_from_other_client(node, ("d", 3.5))()
    r = d.wait(timeout=0)
    assert r is not None and r.value == 3.5
    t0 = time.monotonic()
    assert d.wait(timeout=0.15) is None
    assert 0.1 < time.monotonic() - t0 < 1.5


def test_signal_wait_does_not_take_client_wait_notification(client: Client, node: str) -> None:
    d = client.signal("d")
    d.read()
    client.wait(timeout=0)  # forget earlier changes
    write_from_other_client(node, ("d", 4.5))()
    r = d.wait(timeout=1.0)
    assert r is not None and r.value == 4.5
    assert client.wait(timeout=0) is True  # Client.wait() keeps its own notion of 'changed'


def test_events_iterator_yields_every_event_in_order(client: Client, node: str) -> None:
    ev = client.signal("ev")
    drain(ev)
    t = later(0.1, write_from_other_client(node, *[("ev", v) for v in (11, 12, 13, 14, 15)]))
    got = [r.value for r in ev.events(timeout=1.0)]
    t.join()
    assert got == [11, 12, 13, 14, 15]


def test_dispatch_calls_callbacks_for_new_values(client: Client, node: str) -> None:
    drain(client.signal("ev"))
    calls: List[Tuple[str, object]] = []
    client.on("ev", lambda s, r: calls.append((s.name, r.value)))
    client.on("vec", lambda s, r: calls.append((s.name, None if r.value is None else list(r.value))))  # type: ignore[arg-type]
    assert client.dispatch(timeout=0.05) == 0
    t = later(0.1, write_from_other_client(node, ("ev", 1), ("ev", 2), ("vec", [1, 2, 3, 4])))
    n = 0
    deadline = time.monotonic() + 3.0
    while n < 3 and time.monotonic() < deadline:
        n += client.dispatch(timeout=1.0)
    t.join()
    assert ("ev", 1) in calls and ("ev", 2) in calls and ("vec", [1.0, 2.0, 3.0, 4.0]) in calls
    assert calls.index(("ev", 1)) < calls.index(("ev", 2))
    with pytest.raises(ValueError):
        Client(node).dispatch(timeout=0)


def test_asyncio_wait_and_events(client: Client, node: str) -> None:
    d, ev = client.signal("d"), client.signal("ev")
    drain(ev)

    async def main() -> Tuple[Reading | None, float, List[object], Reading | None, int]:
        ticks = 0

        async def ticker() -> None:  # the loop must keep running while we wait
            nonlocal ticks
            while True:
                await asyncio.sleep(0.01)
                ticks += 1

        tick_task = asyncio.create_task(ticker())
        t0 = time.monotonic()
        th = later(0.2, write_from_other_client(node, ("f", 2.0), ("d", 6.5)))
        r = await d.wait_async(timeout=5.0)
        dt = time.monotonic() - t0
        th.join()
        th = later(0.1, write_from_other_client(node, ("ev", 7), ("ev", 8), ("ev", 9)))
        got: List[object] = [x.value async for x in ev.aevents(timeout=1.0)]
        th.join()
        timed_out = await d.wait_async(timeout=0.1)
        tick_task.cancel()
        return r, dt, got, timed_out, ticks

    r, dt, got, timed_out, ticks = asyncio.run(main())
    assert r is not None and r.value == 6.5
    assert 0.15 < dt < 3.0
    assert got == [7, 8, 9]
    assert timed_out is None
    assert ticks > 20  # the event loop ran during the waits


def test_asyncio_dispatch_and_a_second_loop(client: Client, node: str) -> None:
    drain(client.signal("ev"))
    seen: List[object] = []
    client.on("ev", lambda s, r: seen.append(r.value))

    async def main() -> int:
        th = later(0.1, write_from_other_client(node, ("ev", 42)))
        n = await client.dispatch_async(timeout=3.0)
        th.join()
        return n

    assert asyncio.run(main()) == 1 and seen == [42]
    assert asyncio.run(main()) == 1 and seen == [42, 42]  # a new event loop works too


def test_version_is_the_project_version() -> None:
    cmake = (REPO / "CMakeLists.txt").read_text()
    m = re.search(r"project\(ccomm VERSION ([0-9.]+)", cmake)
    assert m and ccomm.__version__ == m.group(1)
    assert importlib.metadata.version("ccomm") == ccomm.__version__


def test_write_while_ccommd_is_down_tells_the_caller(build_dir: Path, node: str, tmp_path: Path) -> None:
    # A ccommd of its own (node 'pydown', local-only), killed without a chance to clean up.
    cfg = tmp_path / "down.xml"
    cfg.write_text('<?xml version="1.0"?>\n<ccomm version="1">\n  <node name="pydown"/>\n'
                   '  <signal name="x" type="double" producer="pydown"/>\n</ccomm>\n')
    log = open(tmp_path / "ccommd.log", "w")
    proc = subprocess.Popen([str(build_dir / "bin" / "ccommd"), "--config", str(cfg), "--node", "pydown",
                             "--no-rt"], stdout=log, stderr=subprocess.STDOUT)
    seg = Path("/dev/shm") / (os.environ["CCOMM_SHM_PREFIX"].lstrip("/") + "pydown")
    try:
        deadline = time.monotonic() + 10
        while True:
            try:
                c = Client("pydown")
                break
            except ccomm.NotFoundError:
                assert proc.poll() is None and time.monotonic() < deadline, (tmp_path / "ccommd.log").read_text()
                time.sleep(0.05)
        with c:
            c.write("x", 1.0)  # alive: no error
            proc.send_signal(signal.SIGKILL)
            proc.wait()
            deadline = time.monotonic() + 5
            while c.daemon_alive and time.monotonic() < deadline:
                time.sleep(0.05)
            assert not c.daemon_alive
            with pytest.raises(ccomm.DaemonNotRunningError) as e:
                c.write("x", 2.0)
            assert "not running" in str(e.value) and "pydown" in str(e.value)
            assert isinstance(e.value, ConnectionError) and isinstance(e.value, ccomm.CcommError)
            assert c.read("x").value == 2.0  # written all the same: the caller decides
        with Client("pydown", check_daemon=False) as quiet:
            quiet.write("x", 3.0)  # asked not to check
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        log.close()
        if seg.exists():
            seg.unlink()


def test_the_wheels_bundled_library_comes_first(tmp_path: Path) -> None:
    from ccomm import _native

    bundled = tmp_path / "site" / "ccomm" / "_lib" / "libccomm.so.0"
    bundled.parent.mkdir(parents=True)
    bundled.write_text("")
    build = tmp_path / "build-x"
    (build / "lib").mkdir(parents=True)
    (build / "lib" / "libccomm.so.0").write_text("")
    env = {"CCOMM_BUILD_DIR": str(build)}
    assert _native.find_library(env, [], bundled) == str(bundled)  # before any build tree
    explicit = tmp_path / "mine.so"
    explicit.write_text("")
    assert _native.find_library({**env, "CCOMM_LIBRARY": str(explicit)}, [], bundled) == str(explicit)
    bundled.unlink()  # a source install has none: the build directory is next
    assert _native.find_library(env, [], bundled) == str(build / "lib" / "libccomm.so.0")


def test_library_path_is_the_mapped_file(client: Client) -> None:
    path = ccomm.library_path()
    assert os.path.isabs(path) and os.path.basename(path).startswith("libccomm.so")
    assert os.path.samefile(path, os.environ["CCOMM_LIBRARY"])
