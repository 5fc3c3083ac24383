# SPDX-License-Identifier: Apache-2.0
"""ProductionAges (the recorder's and the live view's production times) follows a ccommd
restarted on the same configuration: the segment stays, the system view is made anew,
and a view kept from before would stop (its clocks time out: every production time
unknown). Its own ccommd, restarted here, so the session's ccommd is left alone."""
from __future__ import annotations

import ctypes
import time
from typing import Callable


import ccomm
from ccomm import _native, _view



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


def test_a_restarted_ccommds_new_view_is_followed(own_ccommd: Callable[..., None]) -> None:
    assert wait_until(_daemon_up, 10), "ccommd did not start"
    c = ccomm.Client("pytest")
    try:
        ages = _view.ProductionAges(c.handle)
        first = ages.raw
        assert first is not None
        assert wait_until(lambda: summaries_sent(first) >= 1, 10)  # the live view counts
        own_ccommd()
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
