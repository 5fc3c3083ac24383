# SPDX-License-Identifier: Apache-2.0
"""Real-time set-up and the periodic sleep of libccomm (ccomm.h ccomm_realtime_setup,
ccomm_sleep_until): the platform layer's one implementation, the same ccommd and ccomm's
programs use, for a Python loop (ccomm record, ccomm replay) as for a C one."""
from __future__ import annotations

import ctypes
from typing import NamedTuple

from . import _native


class RealtimeResult(NamedTuple):
    """Each part's result: 0 (done, or not asked for) or a negative errno."""

    cpu: int
    lock_memory: int
    priority: int

    @property
    def ok(self) -> bool:
        return self.cpu == 0 and self.lock_memory == 0 and self.priority == 0


def realtime_setup(cpu: int = -1, lock_memory: bool = False, priority: int = 0) -> RealtimeResult:
    """Pins the calling thread to `cpu` (< 0: leave it), locks the process's memory
    (mlockall(MCL_CURRENT | MCL_FUTURE) on Linux) and gives the thread SCHED_FIFO
    `priority` (0: leave it), in that order; what cannot be done is said in the result
    (-EPERM without the privilege) and the rest is still done. Call it once, before the loop."""
    errors = (ctypes.c_int32 * 3)()
    _native.lib().ccomm_realtime_setup(int(cpu), 1 if lock_memory else 0, int(priority), errors)
    return RealtimeResult(int(errors[0]), int(errors[1]), int(errors[2]))


def sleep_until(deadline_ns: int) -> bool:
    """Sleeps until ccomm_now() reaches `deadline_ns` (absolute: a periodic loop keeps its
    rate). True at the deadline, False if a signal handler ran first."""
    r = int(_native.lib().ccomm_sleep_until(int(deadline_ns)))
    if r < 0:
        raise ValueError(f"sleep_until: negative deadline {deadline_ns}")
    return r == 0
