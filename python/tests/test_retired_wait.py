# SPDX-License-Identifier: Apache-2.0
"""A Client waiting when ccommd restarts with a new configuration is told so: wait()
(Client.wait, and a coroutine's wait_async) raises RetiredError instead of sleeping on
the replaced segment forever (docs/integrations/python.md, RetiredError). Its own
ccommd under a prefix of its own, so the session's ccommd is left alone."""
from __future__ import annotations

import asyncio
import threading
import time
from typing import Callable, List

import pytest

import ccomm

DEADLINE_S = 20.0  # a loaded machine; the wake-up itself is immediate


def wait_for_segment() -> None:
    deadline = time.monotonic() + DEADLINE_S
    while True:
        try:
            ccomm.Client("pytest").close()
            return
        except ccomm.NotFoundError:
            assert time.monotonic() < deadline, "ccommd did not create its segment"
            time.sleep(0.05)


def test_wait_raises_retired_when_ccommd_changes_configuration(own_ccommd: Callable[..., None]) -> None:
    wait_for_segment()
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
    own_ccommd('stale_after_ms="300"', 'stale_after_ms="400"')  # a local setting: same hash, but a new segment
    for t in threads:
        t.join(DEADLINE_S)
    assert outcome and isinstance(outcome[0], ccomm.RetiredError), outcome
    assert async_outcome and isinstance(async_outcome[0], ccomm.RetiredError), async_outcome
    with pytest.raises(ccomm.RetiredError):
        c.wait(timeout=0)
