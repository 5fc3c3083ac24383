# SPDX-License-Identifier: Apache-2.0
"""Client, Signal and Reading: typed access to one node's ccomm signals."""
from __future__ import annotations

import ctypes
import math
import time
from typing import TYPE_CHECKING, Any, AsyncIterator, Callable, Dict, Iterator, List, Optional

import numpy as np
import numpy.typing as npt

from . import _aio, _native, _view

if TYPE_CHECKING:
    from .history import History
# The exceptions live in _errors; "X as X" keeps ccomm.client.X working (and typed).
from ._errors import _check
from ._errors import (
    BusyError as BusyError,
    CcommError as CcommError,
    DaemonNotRunningError as DaemonNotRunningError,
    InvalidArgumentError as InvalidArgumentError,
    NotFoundError as NotFoundError,
    NotProducerError as NotProducerError,
    QueueFullError as QueueFullError,
    RetiredError as RetiredError,
    SystemCallError as SystemCallError,
    TypeMismatchError as TypeMismatchError,
    VersionError as VersionError,
)

# The descriptors live in _types; "X as X" keeps ccomm.client.X working (and typed).
from ._types import STATUS_NAMES as STATUS_NAMES
from ._types import STRUCT_CODES as STRUCT_CODES
from ._types import TYPE_FORMATS as TYPE_FORMATS
from ._types import _DTYPES as _DTYPES
from ._types import Reading as Reading
from ._types import Scalar as Scalar
from ._types import SignalInfo as SignalInfo
from ._types import SignalType as SignalType
from ._types import Status as Status
from ._types import Value as Value
from ._types import ValueLike as ValueLike

_INFO_SAFE_VALUE = 0x1  # CCOMM_INFO_SAFE_VALUE


class Signal:
    """A signal of the client's node. Get one with Client.signal(name)."""

    def __init__(self, client: "Client", info: SignalInfo) -> None:
        self._client = client
        self.info = info
        # One buffer per signal, reused by every read and write (no allocation in C).
        self._buf = (ctypes.c_ubyte * info.value_bytes)()
        self._view: npt.NDArray[Any] = np.frombuffer(memoryview(self._buf), dtype=info.dtype,
                                                     count=info.count)
        self._cinfo = _native.Info()
        # Sequence number of the newest value this object has handed out: wait() and
        # events() wait for a newer one. A state starts at its current value.
        self._last_seq = 0 if info.is_event else self._peek_seq()

    def _peek_seq(self) -> int:
        status = self._read_raw()
        return 0 if status == Status.EMPTY else int(self._cinfo.seq)

    @property
    def name(self) -> str:
        return self.info.name

    def __repr__(self) -> str:
        i = self.info
        shape = f"[{i.count}]" if i.count != 1 else ""
        return f"<Signal {i.name} {i.type.name.lower()}{shape} {'event' if i.is_event else 'state'}>"

    def _read_raw(self) -> Status:
        r = _native.lib().ccomm_read(self._client._handle(), self.info.id, self._buf,
                                     self.info.value_bytes, ctypes.byref(self._cinfo))
        status = Status(_check(r, f"read {self.info.name}"))
        if status == Status.NEVER and not self._cinfo.flags & _INFO_SAFE_VALUE:
            ctypes.memset(self._buf, 0, self.info.value_bytes)
        return status

    def _reading(self, status: Status, value: Optional[Value]) -> Reading:
        ci = self._cinfo
        if status == Status.EMPTY:
            return Reading(None, status, 0, None, 0, int(ci.lost), False)
        return Reading(value, status, int(ci.seq), None if ci.age_ns < 0 else int(ci.age_ns),
                       int(ci.source_time_ns), int(ci.lost), bool(ci.flags & _INFO_SAFE_VALUE))

    def read(self) -> Reading:
        """State signal: the current value. Event signal: the next event, or EMPTY.
        Never-received values are 0 unless a safe value is configured."""
        self._cinfo.flags = 0
        status = self._read_raw()
        if status == Status.EMPTY:
            return self._reading(status, None)
        return self._value_reading(status)

    def _value_reading(self, status: Status) -> Reading:
        """The Reading of what _read_raw() left in the buffer; remembers its seq."""
        value: Value
        if self.info.count == 1:
            value = self._view[0].item()
        else:
            value = self._view.copy()
        self._last_seq = int(self._cinfo.seq)
        return self._reading(status, value)

    def _take_new(self) -> Optional[Reading]:
        """The next event, or a state value newer than the last one handed out; else None."""
        self._cinfo.flags = 0
        status = self._read_raw()
        if status == Status.EMPTY:
            return None
        if not self.info.is_event and int(self._cinfo.seq) == self._last_seq:
            return None
        return self._value_reading(status)

    def wait(self, timeout: Optional[float] = None) -> Optional[Reading]:
        """Waits for this one signal: the next event, or for a state a value newer than
        the last one this Signal returned (from read(), wait(), events() or at creation).
        Returns its Reading, or None after `timeout` seconds (None: no limit; 0: just
        look). Other signals' changes do not end the wait. Releases the GIL; Ctrl-C works."""
        deadline = None if timeout is None else time.monotonic() + max(0.0, timeout)
        while True:
            r = self._take_new()
            if r is not None:
                return r
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return None
            self._client._wait_for_change(left)

    def events(self, timeout: Optional[float] = None) -> Iterator[Reading]:
        """Iterates over the signal's new values as they come: every event of an event
        signal (none is lost unless the queue overruns: Reading.lost counts those), every
        new value of a state (a state written faster than you iterate skips values). Ends
        when nothing new comes for `timeout` seconds (None: never)."""
        while True:
            r = self.wait(timeout)
            if r is None:
                return
            yield r

    async def wait_async(self, timeout: Optional[float] = None) -> Optional[Reading]:
        """wait() for asyncio: the coroutine sleeps, the event loop runs on."""
        loop_deadline = None if timeout is None else time.monotonic() + max(0.0, timeout)
        pump = self._client._pump
        while True:
            changed = pump.changed_event()  # before the look: a change after it sets this
            r = self._take_new()
            if r is not None:
                return r
            left = None if loop_deadline is None else loop_deadline - time.monotonic()
            if left is not None and left <= 0:
                return None
            await pump.wait(changed, left)

    async def aevents(self, timeout: Optional[float] = None) -> AsyncIterator[Reading]:
        """events() for asyncio: `async for r in signal.aevents(): ...`."""
        while True:
            r = await self.wait_async(timeout)
            if r is None:
                return
            yield r

    def history(self, back: int = 1) -> "History":
        """Every value of this received state from `back` values before the next one on
        (1: the newest kept too), through the node's history tap (see ccomm.history)."""
        from .history import History
        return History(self, back)

    @property
    def history_depth(self) -> int:
        """Values of this signal the node's history tap keeps (0: none, see <node history=>)."""
        return max(0, int(_native.lib().ccomm_history_depth(self._client._handle(), self.info.id)))

    def stats(self) -> Dict[str, int]:
        """ccommd's counters of this signal on this node (ccomm_signal_stats: writes, tx,
        coalesced, rx, lost, stale, ...; what `ccomm stats` prints per signal)."""
        out = _native.SignalStats()
        _check(_native.lib().ccomm_get_signal_stats_sized(self._client._handle(), self.info.id, ctypes.byref(out),
                                                          ctypes.sizeof(out)),
               f"stats of {self.info.name}")
        return {name: int(getattr(out, name)) for name, _t in out._fields_}

    def read_into(self, out: npt.NDArray[Any]) -> Reading:
        """Reads into `out` (shape (count,), the signal's dtype), allocating no array.
        The Reading's value is `out` (None for EMPTY; `out` then keeps its contents)."""
        if out.shape != (self.info.count,) or out.dtype != self.info.dtype:
            raise ValueError(f"{self.info.name}: out must have shape ({self.info.count},) and dtype "
                             f"{self.info.dtype}, not {out.shape} {out.dtype}")
        status = self._read_raw()
        if status == Status.EMPTY:
            return self._reading(status, None)
        out[...] = self._view
        return self._reading(status, out)

    def write(self, value: ValueLike) -> None:
        """Writes a value this node produces: a scalar for count 1, else `count` values
        (or one value for every element). Integers must be integral and in range."""
        i = self.info
        arr = np.asarray(value)
        if arr.ndim > 1 or (arr.ndim == 1 and arr.size not in (1, i.count)) or arr.size == 0:
            raise ValueError(f"{i.name}: expected {i.count} value(s), got shape {arr.shape}")
        if arr.dtype.kind not in "biuf":
            raise TypeError(f"{i.name}: cannot write {arr.dtype} values to a {i.type.name.lower()} signal")
        if i.dtype.kind in "iu" or i.dtype.kind == "b":
            if arr.dtype.kind == "f" and not np.all(np.isfinite(arr) & (arr == np.round(arr))):
                raise ValueError(f"{i.name}: {i.type.name.lower()} signal needs integral values, got {value!r}")
            if i.dtype.kind == "b":
                if not np.all((arr == 0) | (arr == 1)):
                    raise ValueError(f"{i.name}: bool signal needs 0/1 or False/True, got {value!r}")
            else:
                info = np.iinfo(i.dtype)
                as_float = arr.astype(np.float64) if arr.dtype.kind == "f" else None
                # Python floats and ints compare exactly (numpy would round int64's max to 2.0**63).
                lo, hi = ((float(as_float.min()), float(as_float.max())) if as_float is not None
                          else (int(arr.min()), int(arr.max())))
                if lo < info.min or hi > info.max:
                    raise OverflowError(f"{i.name}: value out of range for {i.type.name.lower()}: {value!r}")
        elif i.dtype.kind == "f" and arr.dtype.kind == "f":
            finite = np.isfinite(arr)  # inf and nan are values; a finite one must stay finite
            if np.any(np.abs(arr[finite]) > np.finfo(i.dtype).max):
                raise OverflowError(f"{i.name}: value out of range for {i.type.name.lower()}: {value!r}")
        self._view[...] = arr.astype(i.dtype)
        L, h = _native.lib(), self._client._handle()
        _check(L.ccomm_write(h, i.id, self._buf, i.value_bytes), f"write {i.name}")
        if self._client._check_daemon and not L.ccomm_daemon_alive(h):
            raise DaemonNotRunningError(-2, f"write {i.name}: the value is in shared memory but "
                                        f"ccommd of node {self._client.node} is not running: "
                                        "nothing forwards it (start ccommd)")


class Client:
    """Attached to one node's ccommd segment. Use one Client per thread (ccomm handles
    are not shared between threads). Closes on exit of a `with` block."""

    def __init__(self, node: Optional[str] = None, *, no_doorbell: bool = False,
                 batch: bool = False, check_daemon: bool = True) -> None:
        """Attaches to `node` (None: $CCOMM_NODE, else the hostname); NotFoundError if
        its ccommd has not made the segment. With check_daemon (the default), a write
        while ccommd is not running raises DaemonNotRunningError after writing. With
        batch, state writes are held until flush() and then leave together (one frame
        per control step: CCOMM_OPEN_BATCH)."""
        self._h: Optional[int] = None
        flags = (_native.OPEN_NO_DOORBELL if no_doorbell else 0) | (_native.OPEN_BATCH if batch else 0)
        self._h = self._open(node, flags)
        self._node_arg, self._flags, self._check_daemon = node, flags, check_daemon
        self._signals: Dict[str, Signal] = {}
        self._waiter: Optional[int] = None  # the handle Signal.wait() waits on
        self._pump = _aio.ChangePump(lambda: self._open(self._node_arg, self._flags))
        self._callbacks: List["tuple[Signal, Callable[[Signal, Reading], Any]]"] = []

    @staticmethod
    def _open(node: Optional[str], flags: int) -> int:
        h = ctypes.c_void_p()
        r = _native.lib().ccomm_open(node.encode() if node is not None else None, flags, ctypes.byref(h))
        _check(r, f"open node {node if node is not None else '(default)'}")
        assert h.value is not None
        return h.value

    def _handle(self) -> int:
        if self._h is None:
            raise ValueError("ccomm client is closed")
        return self._h

    @property
    def handle(self) -> int:
        """The ccomm_client* as an address, for direct calls through ccomm._native.lib()
        (the record and replay loops); valid until close()."""
        return self._handle()

    def flush(self) -> None:
        """Batch client (Client(batch=True)): hands every state value written since the
        last flush to ccommd at once (ccomm_flush); otherwise does nothing."""
        _check(_native.lib().ccomm_flush(self._handle()), "flush")

    @property
    def node(self) -> str:
        n: Optional[bytes] = _native.lib().ccomm_node_name(self._handle())
        return n.decode() if n else ""

    @property
    def closed(self) -> bool:
        return self._h is None

    def close(self) -> None:
        if self._h is not None:
            self._pump.close()
            if self._waiter is not None:
                _native.lib().ccomm_close(self._waiter)
                self._waiter = None
            _native.lib().ccomm_close(self._h)
            self._h = None

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass

    def _describe(self, sid: int) -> SignalInfo:
        d = _native.SignalDesc()
        _check(_native.lib().ccomm_describe_sized(self._handle(), sid, ctypes.byref(d), ctypes.sizeof(d)),
               f"describe {sid}")
        return SignalInfo(id=sid, name=(d.name or b"").decode(), type=SignalType(d.type),
                          count=int(d.count), value_bytes=int(d.value_bytes),
                          is_event=bool(d.is_event), produced_here=bool(d.produced_here),
                          stale_after_ms=int(d.stale_after_ms), producer=(d.producer or b"").decode(),
                          consumed_here=bool(d.consumed_here), forwarded=bool(d.forwarded))

    def signals(self) -> List[SignalInfo]:
        """Every signal of the system, in configuration order."""
        n = _check(_native.lib().ccomm_signal_count(self._handle()), "signal count")
        return [self._describe(i) for i in range(n)]

    def signal(self, name: str) -> Signal:
        """The signal called `name` (raises NotFoundError)."""
        s = self._signals.get(name)
        if s is None:
            sid = _native.lib().ccomm_find(self._handle(), name.encode())
            _check(sid, f"signal {name!r} on node {self.node}")
            s = Signal(self, self._describe(sid))
            self._signals[name] = s
        return s

    def __getitem__(self, name: str) -> Signal:
        return self.signal(name)

    def __iter__(self) -> Iterator[SignalInfo]:
        return iter(self.signals())

    def read(self, name: str) -> Reading:
        return self.signal(name).read()

    def write(self, name: str, value: ValueLike) -> None:
        self.signal(name).write(value)

    def set_time(self, t_ns: int = 0) -> None:
        """Cycle time: this client's reads judge freshness and age against `t_ns`
        (CLOCK_MONOTONIC ns, e.g. Client.now()) and its writes are stamped with it, until
        the next call; 0 returns to reading the clock in every call."""
        _check(_native.lib().ccomm_set_time(self._handle(), int(t_ns)), "set_time")

    @staticmethod
    def now() -> int:
        """CLOCK_MONOTONIC in ns: the clock of every ccomm time stamp and age."""
        return int(_native.lib().ccomm_now())

    def wait(self, timeout: Optional[float] = None) -> bool:
        """Blocks until a signal of this node has changed since the previous wait()
        returned, or since the open (True), or `timeout` seconds pass (False); None waits
        forever, 0 just looks. A write between your reads and this call is not missed.
        Releases the GIL while waiting."""
        ms = -1 if timeout is None else max(0, int(math.ceil(timeout * 1000.0)))
        return _check(_native.lib().ccomm_wait(self._handle(), ms), "wait") == 1

    def _wait_for_change(self, timeout: Optional[float]) -> None:
        """One ccomm_wait() on the handle of Signal.wait(), at most 0.2 s at a time (so
        Ctrl-C is seen); a separate handle, so Client.wait() keeps its own notion of
        'changed since the previous wait'."""
        self._handle()
        if self._waiter is None:
            self._waiter = self._open(self._node_arg, self._flags)
        ms = 200 if timeout is None else max(0, min(200, int(math.ceil(timeout * 1000.0))))
        _check(_native.lib().ccomm_wait(self._waiter, ms), "wait")

    def on(self, name: str, callback: Callable[[Signal, Reading], Any]) -> None:
        """Calls callback(signal, reading) from dispatch() for every new value of `name`
        (every event of an event signal, each new value of a state)."""
        self._callbacks.append((self.signal(name), callback))

    def dispatch(self, timeout: Optional[float] = None) -> int:
        """Waits until a signal registered with on() has something new (or `timeout`
        seconds pass; None: no limit) and calls the callbacks for everything new, in
        registration order, events all drained. Returns how many calls it made. Run it in
        a loop: `while True: client.dispatch()`."""
        if not self._callbacks:
            raise ValueError("dispatch(): no callbacks (register them with Client.on())")
        deadline = None if timeout is None else time.monotonic() + max(0.0, timeout)
        while True:
            calls = self._dispatch_round()
            if calls:
                return calls
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return 0
            self._wait_for_change(left)

    def _dispatch_round(self) -> int:
        calls = 0
        for sig, cb in self._callbacks:
            r = sig._take_new()
            while r is not None:
                cb(sig, r)
                calls += 1
                r = sig._take_new() if sig.info.is_event else None
        return calls

    async def dispatch_async(self, timeout: Optional[float] = None) -> int:
        """dispatch() for asyncio: the coroutine sleeps until a registered signal has
        something new; the callbacks run on the event loop's thread."""
        if not self._callbacks:
            raise ValueError("dispatch_async(): no callbacks (register them with Client.on())")
        deadline = None if timeout is None else time.monotonic() + max(0.0, timeout)
        while True:
            changed = self._pump.changed_event()  # before the look (see _aio)
            calls = self._dispatch_round()
            if calls:
                return calls
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return 0
            await self._pump.wait(changed, left)

    @property
    def daemon_alive(self) -> bool:
        """ccommd updated its heartbeat within the last second."""
        return bool(_native.lib().ccomm_daemon_alive(self._handle()))

    def production_age(self, name: str, reading: Reading) -> Dict[str, Any]:
        """How long ago the producer wrote the value `reading` (a read of signal `name`)
        holds, on the boards' common (PTP) time base, as of now: {"known", "code",
        "age_ns", "error_ns", "production_time_ns"} (the write on the common base:
        CLOCK_REALTIME ns). known is False, the numbers None, unless both
        clocks are synced (code "synced": the age is within +/- error_ns) or the value was
        produced on this node ("same_node": exact). docs/design.md, "Time"."""
        sig = self.signal(name)
        return _view.production_age(self._handle(), sig.info.id, reading.seq, reading.source_time_ns)

    def system_view(self) -> Dict[str, Any]:
        """Every node of the system as this board's ccommd knows it from the node
        summaries: the same dict as `ccomm stats --all --json` (nodes with alive, peers,
        counters, and per signal role, rate, lost, stale, age_ms; None for never)."""
        return _view.system_view(self._handle())
