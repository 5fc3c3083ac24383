# SPDX-License-Identifier: Apache-2.0
"""Every value of a received state signal: the node's history tap (ccomm_history_*).

    with ccomm.Client("monitor") as c:
        h = c["wheel0_pos"].history()        # from the newest value kept
        for r in h.drain():                  # every value since, in order
            print(r.seq, r.value, r.receive_time_ns)
        h.overrun                            # values this reader fell too far behind for

Needs <node name="monitor" history="N"> in signals.xml; Signal.history() raises
NotFoundError for a signal the node keeps no history of (an event, a signal it produces,
or a node without history=).
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Iterator, Optional

import numpy as np
import numpy.typing as npt

from . import _native
from ._errors import _check
from ._types import Status

if TYPE_CHECKING:
    from .client import Signal, Value

_EMPTY = int(Status.EMPTY)  # a plain int: compared with every call's result


@dataclass(frozen=True)
class HistoryReading:
    """One value from the history: what ccommd stored, in order."""

    value: "Value"  #: scalar for count 1, numpy array otherwise
    seq: int  #: producer's sequence number
    source_time_ns: int  #: producer's CLOCK_MONOTONIC when it wrote the value
    receive_time_ns: int  #: this node's CLOCK_MONOTONIC when ccommd stored it
    overrun: int  #: values this reader missed so far (it fell more than the depth behind)
    lost: int  #: values that never reached this node (gaps seen by ccommd)


class History:
    """A reader's cursor over one signal's history ring; get one with Signal.history()."""

    def __init__(self, signal: "Signal", back: int = 1) -> None:
        self._signal = signal
        info = signal.info
        self.depth = int(_native.lib().ccomm_history_depth(signal._client._handle(), info.id))
        #: the ccomm_history_cursor (for direct ccomm_history_read calls, as ccomm-record makes)
        self.cursor = _native.HistoryCursor()
        _check(_native.lib().ccomm_history_start(signal._client._handle(), info.id, back,
                                                 ctypes.byref(self.cursor)),
               f"history of {info.name}")
        self._buf = (ctypes.c_ubyte * info.value_bytes)()
        self._view: npt.NDArray[Any] = np.frombuffer(memoryview(self._buf), dtype=info.dtype,
                                                     count=info.count)
        self._info = _native.HistoryInfo()

    @property
    def overrun(self) -> int:
        """Values this reader missed because it fell more than `depth` values behind."""
        return int(self.cursor.overrun)

    def read(self) -> Optional[HistoryReading]:
        """The next value, or None when the reader has caught up."""
        s = self._signal
        r = _native.lib().ccomm_history_read(s._client._handle(), s.info.id, ctypes.byref(self.cursor),
                                             self._buf, s.info.value_bytes, ctypes.byref(self._info))
        if _check(r, f"history of {s.info.name}") == _EMPTY:
            return None
        i = self._info
        value = self._view[0].item() if s.info.count == 1 else self._view.copy()
        return HistoryReading(value, int(i.seq), int(i.source_time_ns), int(i.receive_time_ns),
                              int(i.overrun), int(i.lost))

    def drain(self) -> Iterator[HistoryReading]:
        """Every value available now, oldest first."""
        while (r := self.read()) is not None:
            yield r
