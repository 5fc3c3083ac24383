# SPDX-License-Identifier: Apache-2.0
"""What the binding says about signals and reads: the status and type enums (ccomm_status,
ccomm_type), the signal descriptor (SignalInfo, from ccomm_describe) and a Reading."""
from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any, Dict, Optional, Union

import numpy as np
import numpy.typing as npt

Scalar = Union[bool, int, float]
Value = Union[Scalar, "npt.NDArray[Any]"]
ValueLike = Union[Scalar, "npt.ArrayLike"]


class Status(enum.IntEnum):
    """What a read says about the value (ccomm_status)."""

    FRESH = 0  #: younger than the signal's stale_after_ms
    STALE = 1  #: older than stale_after_ms (the safe value if one is configured)
    NEVER = 2  #: nothing received since the node's segment was created
    EMPTY = 3  #: event signal: no new event since the last read


class SignalType(enum.IntEnum):
    """ccomm_type; a type's name (ccomm_type_name) is its member name in lower case."""

    BOOL = 1
    INT32 = 2
    UINT32 = 3
    INT64 = 4
    FLOAT = 5
    DOUBLE = 6

    @property
    def type_name(self) -> str:
        """"bool", "int32", ... "double": the name signals.xml and ccomm(1) use."""
        return self.name.lower()

    @property
    def json_type(self) -> str:
        """The JSON Schema type of a value: boolean, integer or number."""
        return {"b": "boolean", "f": "number"}.get(_DTYPES[self].kind, "integer")


#: Status names as recordings and ccomm(1) write them: "fresh", "stale", "never", "empty".
STATUS_NAMES = tuple(s.name.lower() for s in Status)


_DTYPES: Dict[SignalType, "np.dtype[Any]"] = {
    SignalType.BOOL: np.dtype(np.bool_),
    SignalType.INT32: np.dtype(np.int32),
    SignalType.UINT32: np.dtype(np.uint32),
    SignalType.INT64: np.dtype(np.int64),
    SignalType.FLOAT: np.dtype(np.float32),
    SignalType.DOUBLE: np.dtype(np.float64),
}

# struct format of one element of each type (little-endian: the segment is host order,
# and every board ccomm runs on is little-endian)
STRUCT_CODES: Dict[SignalType, str] = {
    SignalType.BOOL: "?", SignalType.INT32: "i", SignalType.UINT32: "I", SignalType.INT64: "q",
    SignalType.FLOAT: "f", SignalType.DOUBLE: "d",
}
#: the same by type name ("double": "d"), for what recordings name
TYPE_FORMATS: Dict[str, str] = {t.type_name: code for t, code in STRUCT_CODES.items()}



@dataclass(frozen=True)
class SignalInfo:
    """Static description of a signal (from signals.xml, as ccommd loaded it)."""

    id: int
    name: str
    type: SignalType
    count: int  #: array length; 1 = scalar
    value_bytes: int
    is_event: bool
    produced_here: bool  #: this node may write it
    stale_after_ms: int  #: 0 = never stale
    producer: str
    consumed_here: bool = False  #: produced elsewhere and delivered to this node
    forwarded: bool = False  #: produced here and consumed by another node (ccommd sends it)

    @property
    def dtype(self) -> "np.dtype[Any]":
        return _DTYPES[self.type]

    @property
    def type_name(self) -> str:
        """"double", "int32", ...: the element type's name."""
        return self.type.type_name

    @property
    def type_text(self) -> str:
        """"double" for a scalar, "double[4]" for an array."""
        return self.type_name if self.count == 1 else f"{self.type_name}[{self.count}]"

    @property
    def readable_here(self) -> bool:
        """This node holds values of the signal (it produces or receives it)."""
        return self.produced_here or self.consumed_here


@dataclass(frozen=True)
class Reading:
    """One read: the value and what ccomm knows about it."""

    value: Optional[Value]  #: scalar for count 1, numpy array otherwise; None if EMPTY
    status: Status
    seq: int  #: producer's sequence number (0 = never)
    age_ns: Optional[int]  #: since the value reached this node; None if never
    source_time_ns: int  #: producer's CLOCK_MONOTONIC when it wrote the value
    lost: int  #: values/events of this signal known lost so far
    safe_value: bool  #: the value is the configured safe value

    @property
    def fresh(self) -> bool:
        return self.status == Status.FRESH
