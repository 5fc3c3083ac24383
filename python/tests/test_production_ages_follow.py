# SPDX-License-Identifier: Apache-2.0
"""ProductionAges (the recorder's and the live view's production times) follows a ccommd
restarted on the same configuration: the segment stays, the system view is made anew,
and a view kept from before would stop (its clocks time out: every production time
unknown). Its own ccommd, restarted here, so the session's ccommd is left alone."""
from __future__ import annotations

import ctypes
import os
import subprocess
import time
from pathlib import Path
from typing import Callable, Iterator

import pytest

import ccomm
from ccomm import _native, _view

HERE = Path(__file__).resolve().parent


def summaries_sent(raw: ctypes.c_void_p) -> int:
    vc = _native.ViewCounters()
    assert _native.lib().ccomm_view_get_counters_sized(raw, ctypes.byref(vc), ctypes.sizeof(vc)) == 0
    return int(vc.summaries_tx)


def wait_until(cond, seconds: float) -> bool:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if cond():
            return True
        time.sleep(0.05)
    return bool(cond())


@pytest.fixture
def restart_daemon(build_dir: Path, node: str, tmp_path: Path) -> Iterator[Callable[[], None]]:
    """A ccommd for node "pytest" under a prefix of its own (the session's `node` fixture
    sets CCOMM_LIBRARY); yields a function that restarts it on the same configuration."""
    saved = os.environ["CCOMM_SHM_PREFIX"]
    prefix = f"/ccomm-pytest-follow-{os.getpid()}."
    os.environ["CCOMM_SHM_PREFIX"] = prefix
    cfg = tmp_path / "signals.xml"
    cfg.write_text((HERE / "signals.xml").read_text().replace("UDP_PORT", str(20000 + os.getpid() % 20000)))
    log = open(tmp_path / "ccommd.log", "w")
    cmd = [str(build_dir / "bin" / "ccommd"), "--config", str(cfg), "--node", "pytest", "--no-rt",
           "--transport", "udp", "--ptp-socket", "none"]
    procs = [subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)]

    def restart() -> None:
        procs[-1].terminate()
        procs[-1].wait(timeout=10)
        procs.append(subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT))

    try:
        yield restart
    finally:
        for p in procs:
            if p.poll() is None:
                p.terminate()
                p.wait(timeout=10)
        log.close()
        os.environ["CCOMM_SHM_PREFIX"] = saved
        for name in ("pytest", "pytest.view"):
            seg = Path("/dev/shm") / (prefix.lstrip("/") + name)
            if seg.exists():
                seg.unlink()


def test_a_restarted_ccommds_new_view_is_followed(restart_daemon: Callable[[], None]) -> None:
    assert wait_until(_daemon_up, 10), "ccommd did not start"
    c = ccomm.Client("pytest")
    try:
        ages = _view.ProductionAges(c.handle)
        first = ages.raw
        assert first is not None
        assert wait_until(lambda: summaries_sent(first) >= 1, 10)  # the live view counts
        restart_daemon()
        assert wait_until(lambda: c.daemon_alive and _generation(c) == 2, 10), "restarted ccommd not alive"
        # The old view no longer moves; follow() (once a second in the loops) opens the new one.
        now = time.monotonic()
        ages.follow(now)
        ages.follow(now + 2.5)  # the second look, 2 s after the restart was seen
        assert ages.raw is not None
        before = summaries_sent(ages.raw)
        assert wait_until(lambda: summaries_sent(ages.raw) > before, 10), "the view followed is not the live one"
        # ... and production ages come from it: this node's value, exact on its own clock.
        c.write("d", 1.0)
        r = c.read("d")
        pa = ages.of(c.signal("d").info.id, r.seq, r.source_time_ns)
        assert pa.known == 1 and _view.age_code_name(pa.code) == "same_node"
        ages.close()
    finally:
        c.close()


def _daemon_up() -> bool:
    try:
        ccomm.Client("pytest").close()
        return True
    except ccomm.NotFoundError:
        return False


def _generation(c: ccomm.Client) -> int:
    return int(_native.lib().ccomm_daemon_generation(c.handle))
