# SPDX-License-Identifier: Apache-2.0
"""Client.system_view(): the view of every node that ccommd gathered from the node
summaries (ccomm.h, ccomm_view_*; what `ccomm stats --all --json` prints)."""
from __future__ import annotations

import ctypes
from typing import Any, Dict, List, Optional

from . import _native
from ._errors import E_NOENT, _check

ROLE_PRODUCER, ROLE_CONSUMER = 1, 2  # ccomm_view_signal.role
_ROLES = {ROLE_PRODUCER: "producer", ROLE_CONSUMER: "consumer"}


def system_view(handle: int) -> Dict[str, Any]:
    L = _native.lib()
    v = ctypes.c_void_p()
    _check(L.ccomm_view_open(handle, ctypes.byref(v)), "system view")
    try:
        vc = _native.ViewCounters()
        _check(L.ccomm_view_get_counters_sized(v, ctypes.byref(vc), ctypes.sizeof(vc)), "system view")
        names: List[str] = []
        nodes: List[Dict[str, Any]] = []
        n_signals = L.ccomm_signal_count(handle)
        for n in range(L.ccomm_node_count(handle)):
            vn = _native.ViewNode()
            _check(L.ccomm_view_get_node_sized(v, n, ctypes.byref(vn), ctypes.sizeof(vn)), "system view")
            names.append(vn.name.decode())
            signals = []
            for s in range(n_signals):
                vs = _native.ViewSignal()
                rc = L.ccomm_view_get_signal_sized(v, n, s, ctypes.byref(vs), ctypes.sizeof(vs))
                if rc == E_NOENT:
                    continue  # the node neither produces nor consumes it (or no report yet)
                _check(rc, "system view")
                signals.append({"name": vs.name.decode(), "role": _ROLES.get(vs.role, str(vs.role)),
                                "rate": vs.rate, "lost": vs.lost, "stale": bool(vs.stale),
                                "age_ms": vs.age_ns / 1e6 if vs.age_ns >= 0 else None})
            nodes.append({"name": names[-1], "self": bool(vn.is_self), "reported": bool(vn.reported),
                          "alive": bool(vn.alive), "age_ms": vn.age_ns / 1e6 if vn.age_ns >= 0 else None,
                          "timeout_ms": vn.timeout_ns / 1e6, "uptime_s": vn.uptime_ns / 1e9,
                          "peers_alive": vn.peers_alive, "frames_rx": vn.frames_rx, "frames_tx": vn.frames_tx,
                          "frames_bad": vn.frames_bad, "frames_lost": vn.frames_lost,
                          "socket_drops": vn.socket_drops, "cycle_ms": vn.cycle_ms, "summaries": vn.summaries,
                          "clock": {"state": L.ccomm_clock_state_name(vn.clock_state).decode(),
                                    "error_ns": vn.clock_error_ns if vn.clock_error_ns >= 0 else None},
                          "signals": signals})
        for node in nodes:  # the bit mask as names, as the CLI prints it
            mask = node["peers_alive"]
            node["peers_alive"] = [names[i] for i in range(min(len(names), 64)) if mask >> i & 1]
        return {"node": L.ccomm_node_name(handle).decode(), "summary_ms": vc.summary_ms,
                "summaries": {"tx": vc.summaries_tx, "rx": vc.summaries_rx, "refused": vc.summaries_refused,
                              "old": vc.summaries_old, "send_errors": vc.summaries_send_errors},
                "nodes": nodes}
    finally:
        L.ccomm_view_close(v)


class ProductionAges:
    """ccomm_view_production_age for many reads: the view is opened once (close() or `with`)
    and the structs are preallocated, so a loop that records or shows every value pays
    one foreign call per value. `of()` fills `out` (a _native.ProductionAge) and returns it."""

    def __init__(self, handle: int) -> None:
        self._lib = _native.lib()
        self._handle = handle
        self._v = ctypes.c_void_p()
        self._generation = self._lib.ccomm_daemon_generation(handle)
        self._recheck_at = 0.0
        _check(self._lib.ccomm_view_open(handle, ctypes.byref(self._v)), "system view")
        self._info = _native.Info()
        self.out = _native.ProductionAge()
        self._info_ref, self._out_ref = ctypes.byref(self._info), ctypes.byref(self.out)
        self._size = ctypes.sizeof(self.out)

    def of(self, signal_id: int, seq: int, source_time_ns: int) -> "_native.ProductionAge":
        """The production age of a read (its seq and source time); code no_summary while
        there is no view (see follow())."""
        self._info.seq, self._info.source_time_ns = seq, source_time_ns
        if not self._v:
            self.out.code, self.out.known = 5, 0
            self.out.age_ns = self.out.error_ns = self.out.production_time_ns = -1
            return self.out
        _check(self._lib.ccomm_view_production_age_sized(self._v, signal_id, self._info_ref, self._out_ref,
                                                         self._size), "production age")
        return self.out

    def follow(self, now: float) -> None:
        """Call about once a second (`now`: time.monotonic()). A ccommd restarted on the same
        configuration keeps the segment but makes a new view (the old one stops: its clocks
        would time out and every production time be unknown). It adopts the segment
        (generation + 1) just before it creates the view: the view is opened again when
        the generation changes and once more 2 s later, in case the first came between.
        Without a view (not there yet) `raw` is None and ages are unknown."""
        generation = self._lib.ccomm_daemon_generation(self._handle)
        restarted = generation != self._generation
        if not restarted and (not self._recheck_at or now < self._recheck_at):
            return
        self._generation, self._recheck_at = generation, (now + 2.0 if restarted else 0.0)
        self.close()
        v = ctypes.c_void_p()
        if self._lib.ccomm_view_open(self._handle, ctypes.byref(v)) == 0:
            self._v = v

    @property
    def raw(self) -> Optional[ctypes.c_void_p]:
        """The ccomm_view pointer, for a loop that makes the call itself (None: no view)."""
        return self._v if self._v else None

    def close(self) -> None:
        if self._v:
            self._lib.ccomm_view_close(self._v)
            self._v = ctypes.c_void_p()

    def __enter__(self) -> "ProductionAges":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def age_code_name(code: int) -> str:
    """The name of a ccomm_production_age_code ("synced", "local_unsynced", ...)."""
    name: bytes = _native.lib().ccomm_production_age_name(code)
    return name.decode()


def production_age(handle: int, signal_id: int, seq: int, source_time_ns: int) -> Dict[str, Any]:
    """ccomm_view_production_age for the value a read returned (its seq and source time)."""
    with ProductionAges(handle) as ages:
        pa = ages.of(signal_id, seq, source_time_ns)
        known = bool(pa.known)
        return {"known": known, "code": age_code_name(pa.code),
                "age_ns": pa.age_ns if known else None, "error_ns": pa.error_ns if known else None,
                "production_time_ns": pa.production_time_ns if known else None}
