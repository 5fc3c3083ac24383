# SPDX-License-Identifier: Apache-2.0
"""asyncio support: one waiting thread per Client turns ccomm_wait() into loop events.

ccomm_wait() blocks, and a handle is used by one thread at a time, so the Client opens a
second handle of its own for this and a single worker thread waits on it, in slices, while
any coroutine waits. Every return of that wait with a change wakes every waiting coroutine,
which then looks at its own signal through the Client's main handle on the loop thread.
No change is missed: a coroutine takes the current `changed` event before it looks, and
only the loop thread replaces that event, so a change after the look sets the event taken.
"""
from __future__ import annotations

import asyncio
import concurrent.futures
import ctypes
from typing import Callable, Optional

from . import _native
from ._errors import error

#: One wait of the worker thread; bounds how long close() and a cancelled wait take.
SLICE_MS = 100


class ChangePump:
    """Wakes coroutines on changes of one node (see the module docstring)."""

    def __init__(self, open_handle: Callable[[], int]) -> None:
        self._open_handle = open_handle
        self._handle: Optional[int] = None
        self._executor: Optional[concurrent.futures.ThreadPoolExecutor] = None
        self._loop: Optional[asyncio.AbstractEventLoop] = None
        self._changed: Optional[asyncio.Event] = None
        self._task: Optional["asyncio.Task[None]"] = None
        self._waiters = 0
        self._error: Optional[BaseException] = None

    def changed_event(self) -> asyncio.Event:
        """The event the next change sets. Take it *before* looking at a signal."""
        loop = asyncio.get_running_loop()
        if self._loop is not loop or self._changed is None:
            # First use, or a new event loop (asyncio.run again): fresh loop objects; the
            # worker thread and the handle carry over.
            self._loop, self._changed, self._task = loop, asyncio.Event(), None
        if self._error is not None:
            err, self._error = self._error, None
            raise err
        return self._changed

    async def wait(self, event: asyncio.Event, timeout: Optional[float]) -> None:
        """Until `event` is set or `timeout` seconds pass (None: no limit)."""
        if event.is_set():
            return
        self._waiters += 1
        try:
            if self._task is None or self._task.done():
                self._task = asyncio.get_running_loop().create_task(self._pump())
            if timeout is None:
                await event.wait()
            else:
                try:
                    await asyncio.wait_for(event.wait(), timeout)
                except asyncio.TimeoutError:
                    pass
        finally:
            self._waiters -= 1

    async def _pump(self) -> None:
        loop = asyncio.get_running_loop()
        if self._handle is None:
            self._handle = self._open_handle()
        if self._executor is None:
            self._executor = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="ccomm-wait")
        handle, L = self._handle, _native.lib()
        while self._waiters > 0:
            try:
                r = await loop.run_in_executor(self._executor, L.ccomm_wait, handle, SLICE_MS)
            except asyncio.CancelledError:  # the loop is closing (asyncio.run ends)
                raise
            except BaseException as e:  # raised in the waiting coroutines, not lost in a task
                self._error = e
                r = 1
            if r != 0 and self._loop is loop and self._changed is not None:
                ev, self._changed = self._changed, asyncio.Event()
                ev.set()
            if r < 0 and self._error is None:
                self._error = error(r, "wait")  # RetiredError: ccommd replaced the segment
            if self._error is not None:
                return

    def close(self) -> None:
        """Stops the worker (after at most one slice) and closes the waiting handle."""
        if self._executor is not None:
            self._executor.shutdown(wait=True)
            self._executor = None
        if self._handle is not None:
            _native.lib().ccomm_close(ctypes.c_void_p(self._handle))
            self._handle = None
