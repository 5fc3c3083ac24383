# SPDX-License-Identifier: Apache-2.0
"""Samples a node's signals into JSON messages, one channel per signal.

Topics, schema names and fields follow `ccomm record` (ccomm.mcap_io.schema), so a
Foxglove layout made for a recording works live too (plot `SIGNAL.value`):

    {"value": 1.5, "seq": 812, "source_time_ns": ..., "receive_time_ns": ...,
     "age_ns": 1200, "status": "fresh", "fresh": true, "safe_value": false,
     "lost": 0, "gap": 0, "production_time_ns": ..., "production_error_ns": 2000,
     "age_code": "synced", "production_age_ns": 41200}

Live only: `age_ns` (at the read, since the value reached this node), `production_age_ns`
(at the read, since the producer wrote it: the end-to-end age on the boards' common time
base, within +/- production_error_ns; null when unknown, age_code says why: then only
the local age_ns is known), status "never" (nothing received yet; value 0, times
null). `gap` counts the values this view did not see between two of its messages: a
signal written faster than the sampling is sampled (`lost` is ccomm's loss counter).

An int64 value (and each element of an int64 array) is a decimal string ("value":
"9007199254744991"): exact, where a JSON number above 2^53 is rounded by JavaScript's and
most other JSON readers. The schema says so (type string, a pattern of digits).

A state signal is published when its sequence number or status changes, and at least
every `keepalive` seconds (its age and a stale transition stay visible without writes);
with `min_interval` (ccomm-web --max-rate) a change that comes sooner than that after
the signal's previous message waits until then (`next_due` says when: the caller's next
pass), and a newer value may replace it (counted in `gap`). Every event of an event
signal is published once (this reader has its own cursor)."""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional

import numpy as np

from .. import _view
from .._errors import CcommError
from ..client import Client, Reading, Signal, SignalInfo, SignalType, Status
from ..mcap_io.schema import AGE_CODES

_STATUS_NAMES = {Status.FRESH: "fresh", Status.STALE: "stale", Status.NEVER: "never"}



def topic_of(name: str) -> str:
    """The channel of a signal: its name, as in a recording."""
    return name


def json_schema(info: SignalInfo) -> Dict[str, Any]:
    """JSON schema of the messages of one signal's channel."""
    value: Dict[str, Any] = {"type": [info.type.json_type, "null"]}
    if info.type == SignalType.INT64:  # exact as text (message_of)
        value = {"type": ["string", "null"], "pattern": "^-?[0-9]+$",
                 "description": "int64 as a decimal string: exact (a JSON number above 2^53 is rounded)"}
    if info.count != 1:
        value = {"type": "array", "items": value, "minItems": info.count, "maxItems": info.count}
    integer, nullable = {"type": "integer"}, {"type": ["integer", "null"]}
    return {
        "title": "ccomm." + info.type.name.lower() + ("[%d]" % info.count if info.count != 1 else ""),
        "type": "object",
        "properties": {
            "value": value,
            "seq": dict(integer, description="producer's sequence number of the value, 0 = never"),
            "source_time_ns": dict(nullable, description="producer's CLOCK_MONOTONIC at the write"),
            "receive_time_ns": dict(nullable, description="this node's CLOCK_MONOTONIC at arrival"),
            "age_ns": dict(nullable, description="since the value reached this node, at the read"),
            "status": {"type": "string", "enum": ["fresh", "stale", "never"]},
            "fresh": {"type": "boolean"},
            "safe_value": {"type": "boolean", "description": "value is the configured safe value"},
            "lost": dict(integer, description="values known lost before this one (cumulative)"),
            "gap": dict(integer, description="values this view did not see just before this one"),
            "production_time_ns": dict(nullable, description="the write on the common time base "
                                       "(CLOCK_REALTIME); null: unknown"),
            "production_error_ns": dict(nullable, description="+/- bound of the production time and age"),
            "age_code": {"type": "string", "enum": list(AGE_CODES),
                         "description": "synced, same_node: production age known; else why not (ages local)"},
            "production_age_ns": dict(nullable, description="since the producer wrote the value, at the read"),
        },
        "required": ["value", "seq", "source_time_ns", "receive_time_ns", "age_ns", "status", "fresh",
                     "safe_value", "lost", "gap", "production_time_ns", "production_error_ns", "age_code",
                     "production_age_ns"],
    }


def message_of(reading: Reading, now_ns: int, gap: int = 0, production: Optional[Any] = None,
               exact_text: bool = False) -> Dict[str, Any]:
    """The JSON message of one read (not EMPTY) made at CLOCK_MONOTONIC `now_ns`, with its
    production age (`production`: a _native.ProductionAge for that read; None: unknown,
    no_summary). NaN and infinities become null: JSON has no spelling for them.
    `exact_text` (int64 signals): the value's integers as decimal strings."""
    value: Any = reading.value
    if isinstance(value, np.ndarray):
        value = [str(v) for v in value.tolist()] if exact_text else [_finite(v) for v in value.tolist()]
    else:
        value = str(int(value)) if exact_text and value is not None else _finite(value)
    never = reading.status == Status.NEVER
    return {"value": value, "seq": reading.seq,
            "source_time_ns": None if never else reading.source_time_ns,
            "receive_time_ns": None if reading.age_ns is None else now_ns - reading.age_ns,
            "age_ns": reading.age_ns, "status": _STATUS_NAMES[reading.status],
            "fresh": reading.status == Status.FRESH, "safe_value": reading.safe_value,
            "lost": reading.lost, "gap": gap, **_production_fields(production)}


def _production_fields(pa: Optional[Any]) -> Dict[str, Any]:
    if pa is None or not pa.known:
        return {"production_time_ns": None, "production_error_ns": None,
                "age_code": AGE_CODES[pa.code] if pa is not None and 0 <= pa.code < len(AGE_CODES) else "no_summary",
                "production_age_ns": None}
    return {"production_time_ns": pa.production_time_ns, "production_error_ns": pa.error_ns,
            "age_code": AGE_CODES[pa.code], "production_age_ns": pa.age_ns}


def _finite(v: Any) -> Any:
    if isinstance(v, float) and (v != v or v in (float("inf"), float("-inf"))):
        return None
    return v


@dataclass
class _Tracked:
    signal: Signal
    last_seq: int = -1
    last_status: Optional[Status] = None
    last_sent: float = 0.0
    published: int = 0
    changes: int = 0  #: messages with a new seq (a new value or event), keepalives not counted
    gaps: int = 0  #: values not seen between two messages (sum of their gap fields)


@dataclass
class Sampler:
    """Reads the chosen signals of `client` and hands each new message to `publish(name,
    message)`. One thread only (the Client's)."""

    client: Client
    names: List[str]
    publish: Callable[[str, Dict[str, Any]], None]
    keepalive: float = 1.0
    min_interval: float = 0.0  #: seconds between two messages of a state at least (0: none)
    next_due: Optional[float] = None  #: when a change held back by min_interval is due (monotonic s)
    _tracked: List[_Tracked] = field(default_factory=list)
    _now_ns: int = 0

    _ages: Optional[_view.ProductionAges] = None
    _followed: float = 0.0

    def __post_init__(self) -> None:
        self._tracked = [_Tracked(self.client.signal(n)) for n in self.names]
        try:  # production ages need the system view (a ccommd older than it has none)
            self._ages = _view.ProductionAges(self.client.handle)
        except CcommError:  # then every age is local, and messages say no_summary
            self._ages = None

    def close(self) -> None:
        if self._ages is not None:
            self._ages.close()
            self._ages = None

    @property
    def published(self) -> Dict[str, int]:
        return {t.signal.name: t.published for t in self._tracked}

    @property
    def changes(self) -> Dict[str, int]:
        return {t.signal.name: t.changes for t in self._tracked}

    @property
    def gaps(self) -> Dict[str, int]:
        return {t.signal.name: t.gaps for t in self._tracked}

    def poll(self, now: Optional[float] = None) -> int:
        """One pass over every signal; returns how many messages were published."""
        now = time.monotonic() if now is None else now
        if self._ages is not None and now - self._followed >= 1.0:
            self._followed = now
            self._ages.follow(now)  # a restarted ccommd's new view
        self._now_ns = self.client.now()  # receive times: one clock reading per pass
        sent = 0
        self.next_due = None
        for t in self._tracked:
            if t.signal.info.is_event:
                # Every queued event once; bounded so one flooded queue cannot starve the rest.
                for _ in range(4096):
                    r = t.signal.read()
                    if r.status == Status.EMPTY:
                        break
                    self._send(t, r, now)
                    sent += 1
                continue
            r = t.signal.read()
            changed = r.seq != t.last_seq or r.status != t.last_status
            if changed and now - t.last_sent < self.min_interval - 1e-6:  # (1 us: float rounding of a due time)
                due = t.last_sent + self.min_interval  # sent then (or its newer value)
                if self.next_due is None or due < self.next_due:
                    self.next_due = due
            elif changed or now - t.last_sent >= self.keepalive:
                self._send(t, r, now)
                sent += 1
        return sent

    def _send(self, t: _Tracked, r: Reading, now: float) -> None:
        if r.seq != t.last_seq or t.signal.info.is_event:
            t.changes += 1
        # From the view's first message on (a signal never written has seq 0 then: its first
        # value replaced before a pass is a gap too); values before the view attached are not.
        gap = r.seq - t.last_seq - 1 if t.last_seq >= 0 and r.seq > t.last_seq + 1 else 0
        t.gaps += gap
        t.last_seq, t.last_status, t.last_sent = r.seq, r.status, now
        t.published += 1
        pa = None
        if self._ages is not None:
            pa = self._ages.of(t.signal.info.id, r.seq, r.source_time_ns)
        self.publish(t.signal.name, message_of(r, self._now_ns, gap, pa, t.signal.info.type == SignalType.INT64))
