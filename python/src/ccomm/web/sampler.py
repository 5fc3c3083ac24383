# SPDX-License-Identifier: Apache-2.0
"""Samples a node's signals into JSON messages, one channel per signal.

A message is what a read says: value, seq, source_time_ns, age_ns, status
("fresh"/"stale"/"never") and lost, the convention `ccomm record` uses too, so
Foxglove plots `/ccomm/SIGNAL.value` and shows freshness next to it.

A state signal is published when its sequence number or status changes, and at least
every `keepalive` seconds (its age and a stale transition stay visible without writes).
Every event of an event signal is published once (this reader has its own cursor)."""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional

import numpy as np

from ..client import Client, Reading, Signal, SignalInfo, SignalType, Status

TOPIC_PREFIX = "/ccomm/"

_STATUS_NAMES = {Status.FRESH: "fresh", Status.STALE: "stale", Status.NEVER: "never"}

_VALUE_SCHEMAS: Dict[SignalType, Dict[str, Any]] = {
    SignalType.BOOL: {"type": "boolean"},
    SignalType.INT32: {"type": "integer"},
    SignalType.UINT32: {"type": "integer"},
    SignalType.INT64: {"type": "integer"},
    SignalType.FLOAT: {"type": "number"},
    SignalType.DOUBLE: {"type": "number"},
}


def topic_of(name: str) -> str:
    return TOPIC_PREFIX + name


def json_schema(info: SignalInfo) -> Dict[str, Any]:
    """JSON schema of the messages of one signal's channel."""
    value: Dict[str, Any] = dict(_VALUE_SCHEMAS[info.type])
    if info.count != 1:
        value = {"type": "array", "items": value, "minItems": info.count, "maxItems": info.count}
    return {
        "title": "ccomm." + info.type.name.lower() + ("[%d]" % info.count if info.count != 1 else ""),
        "type": "object",
        "properties": {
            "value": value,
            "seq": {"type": "integer", "description": "producer's sequence number, 0 = never written"},
            "source_time_ns": {"type": "integer", "description": "producer's CLOCK_MONOTONIC at the write"},
            "age_ns": {"type": ["integer", "null"], "description": "since the value reached this node"},
            "status": {"type": "string", "enum": ["fresh", "stale", "never"]},
            "lost": {"type": "integer", "description": "values/events of this signal known lost"},
        },
        "required": ["value", "seq", "source_time_ns", "age_ns", "status", "lost"],
    }


def message_of(reading: Reading) -> Dict[str, Any]:
    """The JSON message of one read (not EMPTY). NaN and infinities become null: JSON has
    no spelling for them."""
    value: Any = reading.value
    if isinstance(value, np.ndarray):
        value = [_finite(v) for v in value.tolist()]
    else:
        value = _finite(value)
    return {"value": value, "seq": reading.seq, "source_time_ns": reading.source_time_ns,
            "age_ns": reading.age_ns, "status": _STATUS_NAMES[reading.status], "lost": reading.lost}


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


@dataclass
class Sampler:
    """Reads the chosen signals of `client` and hands each new message to `publish(name,
    message)`. One thread only (the Client's)."""

    client: Client
    names: List[str]
    publish: Callable[[str, Dict[str, Any]], None]
    keepalive: float = 1.0
    _tracked: List[_Tracked] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._tracked = [_Tracked(self.client.signal(n)) for n in self.names]

    @property
    def published(self) -> Dict[str, int]:
        return {t.signal.name: t.published for t in self._tracked}

    @property
    def changes(self) -> Dict[str, int]:
        return {t.signal.name: t.changes for t in self._tracked}

    def poll(self, now: Optional[float] = None) -> int:
        """One pass over every signal; returns how many messages were published."""
        now = time.monotonic() if now is None else now
        sent = 0
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
            if r.seq != t.last_seq or r.status != t.last_status or now - t.last_sent >= self.keepalive:
                self._send(t, r, now)
                sent += 1
        return sent

    def _send(self, t: _Tracked, r: Reading, now: float) -> None:
        if r.seq != t.last_seq or t.signal.info.is_event:
            t.changes += 1
        t.last_seq, t.last_status, t.last_sent = r.seq, r.status, now
        t.published += 1
        self.publish(t.signal.name, message_of(r))
