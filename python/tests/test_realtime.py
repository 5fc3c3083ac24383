# SPDX-License-Identifier: Apache-2.0
"""ccomm.realtime_setup and ccomm.sleep_until: libccomm's one set-up and periodic sleep,
what ccomm record and ccomm replay use instead of os.sched_setscheduler and a ctypes
mlockall. No ccommd needed."""
import os
import time

import pytest

import ccomm


def test_nothing_asked_is_nothing_failed():
    r = ccomm.realtime_setup()
    assert r == (0, 0, 0) and r.ok


def test_a_part_that_cannot_be_done_is_said_and_the_others_still_are():
    r = ccomm.realtime_setup(cpu=100000)
    assert r.cpu < 0 and not r.ok
    assert r.lock_memory == 0 and r.priority == 0
    # Pinned in a child: the test process keeps every CPU it had.
    cpu = min(os.sched_getaffinity(0))
    pid = os.fork()
    if pid == 0:
        r = ccomm.realtime_setup(cpu=cpu)
        os._exit(0 if r.ok and os.sched_getaffinity(0) == {cpu} else 1)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, "the child was not pinned to CPU %d" % cpu


def test_sleep_until_keeps_an_absolute_deadline():
    deadline = time.monotonic_ns() + 20_000_000  # ccomm_now() is CLOCK_MONOTONIC
    assert ccomm.sleep_until(deadline) is True
    assert time.monotonic_ns() >= deadline
    t0 = time.monotonic_ns()
    assert ccomm.sleep_until(t0 - 1_000_000) is True  # past: at once
    assert time.monotonic_ns() - t0 < 10_000_000
    with pytest.raises(ValueError):
        ccomm.sleep_until(-1)
