# SPDX-License-Identifier: Apache-2.0
"""A Client waiting when ccommd restarts with a new configuration is told so: wait()
(Client.wait, and a coroutine's wait_async) raises RetiredError instead of sleeping on
the replaced segment forever (docs/integrations/python.md, RetiredError). Its own
ccommd under a prefix of its own, so the session's ccommd is left alone."""
from __future__ import annotations

import asyncio
import os
import subprocess
import threading
import time
from pathlib import Path
from typing import Callable, Iterator, List

import pytest

import ccomm

HERE = Path(__file__).resolve().parent
DEADLINE_S = 20.0  # a loaded machine; the wake-up itself is immediate


@pytest.fixture
def daemon(build_dir: Path, node: str, tmp_path: Path) -> Iterator[Callable[[str], None]]:
    """Starts ccommd for node "pytest"; yields restart(text) that restarts it with the
    configuration text changed by `text` (a replacement for stale_after_ms="300")."""
    saved = os.environ["CCOMM_SHM_PREFIX"]
    prefix = f"/ccomm-pytest-retired-{os.getpid()}."
    os.environ["CCOMM_SHM_PREFIX"] = prefix
    base = (HERE / "signals.xml").read_text().replace("UDP_PORT", str(20000 + (os.getpid() + 7) % 20000))
    cfg = tmp_path / "signals.xml"
    cfg.write_text(base)
    log = open(tmp_path / "ccommd.log", "w")
    cmd = [str(build_dir / "bin" / "ccommd"), "--config", str(cfg), "--node", "pytest", "--no-rt",
           "--transport", "udp", "--ptp-socket", "none"]
    procs: List[subprocess.Popen[bytes]] = [subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)]

    def restart(stale: str) -> None:
        procs[-1].terminate()
        procs[-1].wait(timeout=10)
        cfg.write_text(base.replace('stale_after_ms="300"', stale))
        procs.append(subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT))

    try:
        deadline = time.monotonic() + DEADLINE_S
        while True:
            try:
                ccomm.Client("pytest").close()
                break
            except ccomm.NotFoundError:
                assert time.monotonic() < deadline, "ccommd did not create its segment"
                time.sleep(0.05)
        yield restart
    finally:
        for p in procs:
            if p.poll() is None:
                p.terminate()
                p.wait(timeout=10)
        log.close()
        os.environ["CCOMM_SHM_PREFIX"] = saved
        for name in ("pytest", "pytest.view", "pytest.lock"):
            seg = Path("/dev/shm") / (prefix.lstrip("/") + name)
            if seg.exists():
                seg.unlink()


def test_wait_raises_retired_when_ccommd_changes_configuration(daemon: Callable[[str], None]) -> None:
    c = ccomm.Client("pytest", check_daemon=False)
    c.wait(timeout=0)  # "changed since the open"
    outcome: List[BaseException] = []

    def waiter() -> None:
        try:
            c.wait(None)
        except BaseException as e:  # noqa: BLE001 - the test looks at what came out
            outcome.append(e)

    async def async_waiter() -> None:
        await asyncio.wait_for(c.signal("f").wait_async(None), DEADLINE_S)

    async_outcome: List[BaseException] = []

    def run_async() -> None:
        try:
            asyncio.run(async_waiter())
        except BaseException as e:  # noqa: BLE001
            async_outcome.append(e)

    threads = [threading.Thread(target=waiter, daemon=True), threading.Thread(target=run_async, daemon=True)]
    for t in threads:
        t.start()
    time.sleep(0.3)  # both asleep (if not, they see the retirement at once: same outcome)
    daemon('stale_after_ms="400"')  # a local setting: same hash, but a new segment
    for t in threads:
        t.join(DEADLINE_S)
    assert outcome and isinstance(outcome[0], ccomm.RetiredError), outcome
    assert async_outcome and isinstance(async_outcome[0], ccomm.RetiredError), async_outcome
    with pytest.raises(ccomm.RetiredError):
        c.wait(timeout=0)
