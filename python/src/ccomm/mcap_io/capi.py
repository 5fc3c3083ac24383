# SPDX-License-Identifier: Apache-2.0
"""libccomm for the record and replay loops.

The loops call ccomm_read / ccomm_write tens of thousands of times a second, so this
module loads its own handle on the library (ccomm._native finds it) and declares every
pointer as a plain address: the loops pass integers, and a read costs one foreign call
and no Python object. Only the public C API (ccomm.h) is used.
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import List, Optional

from .. import _native

OPEN_BATCH = 0x2  # CCOMM_OPEN_BATCH: writes are sent together by ccomm_flush()
E_NOENT, E_TYPE, E_PERM, E_FULL, E_BUSY, E_CORRUPT = -2, -3, -4, -5, -6, -10
STATUS_NAMES = ("fresh", "stale", "never", "empty")
TYPE_NAMES = {1: "bool", 2: "int32", 3: "uint32", 4: "int64", 5: "float", 6: "double"}
# struct format of one element of each type (little-endian: the segment is host order,
# and every board ccomm runs on is little-endian)
TYPE_FORMATS = {"bool": "?", "int32": "i", "uint32": "I", "int64": "q", "float": "f", "double": "d"}
# ccomm_info as bytes: status, flags, seq, age_ns, source_time_ns, lost
INFO_FORMAT = "<iIQqQQ"
# ccomm_history_info as bytes: seq, source_time_ns, receive_time_ns, overrun, lost
HISTORY_INFO_FORMAT = "<QQQQQ"
HISTORY_CURSOR_BYTES = 5 * 8  # ccomm_history_cursor
# ccomm_signal_stats: writes, write_errors, tx, coalesced, rx, lost, overflow,
# stale_transitions, corrupt, last_rx_age_ns, stale (+ padding)
SIGNAL_STATS_BYTES, SIGNAL_STATS_TX_OFFSET = 88, 16


class CcommCallError(RuntimeError):
    """A libccomm call failed; the message names the call and the ccomm error."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


@dataclass(frozen=True)
class SignalDesc:
    id: int
    name: str
    type: str  #: bool, int32, uint32, int64, float, double
    count: int
    value_bytes: int
    is_event: bool
    produced_here: bool
    consumed_here: bool
    producer: str
    stale_after_ms: int

    @property
    def readable_here(self) -> bool:
        """This node holds values of the signal (it produces or receives it)."""
        return self.produced_here or self.consumed_here

    @property
    def type_text(self) -> str:
        return self.type if self.count == 1 else f"{self.type}[{self.count}]"


class Handle:
    """One ccomm_open handle, with the raw calls the loops need."""

    def __init__(self, node: Optional[str], flags: int = 0) -> None:
        L = ctypes.CDLL(_native.find_library())
        vp, i32, i64 = ctypes.c_void_p, ctypes.c_int32, ctypes.c_int64
        L.ccomm_open.argtypes = [ctypes.c_char_p, ctypes.c_uint32, ctypes.POINTER(vp)]
        L.ccomm_close.argtypes = [vp]
        L.ccomm_close.restype = None
        L.ccomm_strerror.argtypes = [ctypes.c_int]
        L.ccomm_strerror.restype = ctypes.c_char_p
        L.ccomm_signal_count.argtypes = [vp]
        L.ccomm_describe.argtypes = [vp, i32, ctypes.POINTER(_native.SignalDesc)]
        L.ccomm_node_name.argtypes = [vp]
        L.ccomm_node_name.restype = ctypes.c_char_p
        L.ccomm_read.argtypes = [vp, i32, vp, ctypes.c_size_t, vp]
        L.ccomm_write.argtypes = [vp, i32, vp, ctypes.c_size_t]
        L.ccomm_flush.argtypes = [vp]
        L.ccomm_wait.argtypes = [vp, ctypes.c_int]  # ctypes releases the GIL while it blocks
        L.ccomm_set_time.argtypes = [vp, i64]
        L.ccomm_now.argtypes = []
        L.ccomm_now.restype = i64
        L.ccomm_daemon_alive.argtypes = [vp]
        L.ccomm_get_signal_stats.argtypes = [vp, i32, vp]
        L.ccomm_history_depth.argtypes = [vp, i32]
        L.ccomm_history_start.argtypes = [vp, i32, ctypes.c_uint32, vp]
        L.ccomm_history_read.argtypes = [vp, i32, vp, vp, ctypes.c_size_t, vp]
        self.lib = L
        h = vp()
        r = L.ccomm_open(node.encode() if node else None, flags, ctypes.byref(h))
        if r != 0:
            where = f"node '{node}'" if node else "the default node ($CCOMM_NODE or the hostname)"
            raise CcommCallError(r, f"cannot attach to {where}: {self.strerror(r)}")
        self.h: Optional[int] = h.value
        self.node = (L.ccomm_node_name(self.h) or b"").decode()
        # The loops' entry points, bound once.
        self.read = L.ccomm_read
        self.write = L.ccomm_write
        self.flush = L.ccomm_flush
        self.wait = L.ccomm_wait
        self.set_time = L.ccomm_set_time
        self.now = L.ccomm_now
        self.history_read = L.ccomm_history_read
        self.get_signal_stats = L.ccomm_get_signal_stats

    def strerror(self, code: int) -> str:
        s: Optional[bytes] = self.lib.ccomm_strerror(code)
        return s.decode() if s else f"error {code}"

    def signals(self) -> List[SignalDesc]:
        n = self.lib.ccomm_signal_count(self.h)
        if n < 0:
            raise CcommCallError(n, f"ccomm_signal_count: {self.strerror(n)}")
        out = []
        for i in range(n):
            d = _native.SignalDesc()
            r = self.lib.ccomm_describe(self.h, i, ctypes.byref(d))
            if r != 0:
                raise CcommCallError(r, f"ccomm_describe({i}): {self.strerror(r)}")
            out.append(SignalDesc(id=i, name=(d.name or b"").decode(), type=TYPE_NAMES.get(d.type, "?"),
                                  count=int(d.count), value_bytes=int(d.value_bytes),
                                  is_event=bool(d.is_event), produced_here=bool(d.produced_here),
                                  consumed_here=bool(d.consumed_here),
                                  producer=(d.producer or b"").decode(),
                                  stale_after_ms=int(d.stale_after_ms)))
        return out

    def history_depth(self, sid: int) -> int:
        """Values of signal `sid` the node's history tap keeps (0: none, see <node history=>)."""
        return max(0, int(self.lib.ccomm_history_depth(self.h, sid)))

    def history_cursor(self, sid: int, back: int) -> "ctypes.Array[ctypes.c_ubyte]":
        """A ccomm_history_cursor on `sid`, `back` values before the next one to arrive."""
        cur = (ctypes.c_ubyte * HISTORY_CURSOR_BYTES)()
        r = self.lib.ccomm_history_start(self.h, sid, back, ctypes.addressof(cur))
        if r != 0:
            raise CcommCallError(r, f"ccomm_history_start({sid}): {self.strerror(r)}")
        return cur

    def daemon_alive(self) -> bool:
        return bool(self.lib.ccomm_daemon_alive(self.h))

    def close(self) -> None:
        if self.h is not None:
            self.lib.ccomm_close(self.h)
            self.h = None
