# SPDX-License-Identifier: Apache-2.0
"""The content of a ccomm recording (see docs/integrations/record.md).

One MCAP channel per signal, topic = the signal's name, message encoding "json", schema
encoding "jsonschema": tools that know MCAP plot the fields without ccomm. A message:

    {"value": 1.5, "seq": 812, "source_time_ns": ..., "receive_time_ns": ...,
     "status": "fresh", "fresh": true, "safe_value": false,
     "lost": 0, "gap": 0, "initial": false,
     "production_time_ns": ..., "production_error_ns": 2000, "age_code": "synced"}

value           a number (bool: true/false), or an array for count > 1; NaN and
                infinities are JSON null (JSON has no such numbers)
seq             the producer's sequence number of the value (1, 2, 3 ... per write)
source_time_ns  the producer's CLOCK_MONOTONIC when it wrote the value
receive_time_ns the recording node's CLOCK_MONOTONIC when the value reached it
status / fresh  ccomm's freshness of the value when read (fresh, stale)
lost            values of the signal ccomm knows were lost before this one (the
                counter of ccomm_info: network gaps and overruns; cumulative)
gap             values the recorder did not see between the previous message and this one
                (a jump in seq); 0 in a complete recording
initial         true for a state's value that was already there when the recording
                started (it arrived before): logged at the start, its own times kept
production_time_ns  when the producer wrote the value on the boards' common time base
                (CLOCK_REALTIME ns since the epoch, as ptp4l disciplines it), within
                +/- production_error_ns; null when unknown (age_code says why)
production_error_ns the bound on that (0 for a value produced on the recording node);
                null when unknown
age_code        ccomm_production_age_code: "synced" (both clocks synced), "same_node"
                (exact), or why the production time is unknown: "local_unsynced",
                "producer_unsynced", "no_summary" (docs/design.md, "Time")

Messages are in log-time order. The MCAP log time is the receive time (for an initial
value, the recording's start), moved to the Unix epoch by the offset between
CLOCK_REALTIME and CLOCK_MONOTONIC at the start of the recording (in the "ccomm" metadata
record). The publish time is the production time when known, else the receive time (so
it is never a producer's monotonic stamp read against another board's clock).
"""
from __future__ import annotations

import json
import struct
from typing import Any, Callable, Dict, Tuple

from ..client import STATUS_NAMES, TYPE_FORMATS, SignalInfo, Status

SCHEMA_ENCODING = "jsonschema"
MESSAGE_ENCODING = "json"
SCHEMA_PREFIX = "ccomm."
METADATA_NAME = "ccomm"
FORMAT_VERSION = "1"

# A captured value as the recorder hands it to the writer: signal id, status, flags, seq,
# receive time, source time, lost, production time (CLOCK_REALTIME, -1 unknown), its error
# bound (-1 unknown), production age code (ccomm_production_age_code); then value_bytes
# bytes of value.
RECORD = struct.Struct("<HBBQqQQqqb")
FLAG_SAFE_VALUE = 0x1
# The signal's first value, received before the recording started: logged at the start.
FLAG_INITIAL = 0x2
# A record with this signal id (and no value bytes) is a watermark: the capture has read
# every value that arrived up to its receive time, so the writer can write those in order.
WATERMARK_ID = 0xFFFF
_FRESH = int(Status.FRESH)  # a plain int: compared for every message
# ccomm_production_age_code by value (ccomm_production_age_name; read once from libccomm
# by the recorder, fixed here so the writer and the schema need no library; held to
# ccomm.h by tests/structure/check_constants.py).
AGE_CODES = ("synced", "same_node", "never", "local_unsynced", "producer_unsynced", "no_summary")


def schema_name(desc: SignalInfo) -> str:
    return SCHEMA_PREFIX + desc.type_text


def json_schema(desc: SignalInfo) -> bytes:
    """JSON Schema of one signal's messages (one schema per type and count)."""
    elem: Dict[str, Any] = {"type": [desc.type.json_type, "null"]}
    value: Dict[str, Any] = elem if desc.count == 1 else {"type": "array", "items": elem,
                                          "minItems": desc.count, "maxItems": desc.count}
    integer = {"type": "integer"}
    schema = {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": schema_name(desc),
        "description": f"a ccomm {desc.type_text} signal value and what ccomm knows about it",
        "type": "object",
        "properties": {
            "value": value,
            "seq": dict(integer, description="producer's sequence number of the value"),
            "source_time_ns": dict(integer, description="producer's CLOCK_MONOTONIC at the write"),
            "receive_time_ns": dict(integer, description="recording node's CLOCK_MONOTONIC at arrival"),
            "status": {"type": "string", "enum": ["fresh", "stale"]},
            "fresh": {"type": "boolean"},
            "safe_value": {"type": "boolean", "description": "value is the configured safe value"},
            "lost": dict(integer, description="values known lost before this one (cumulative)"),
            "gap": dict(integer, description="values the recorder missed just before this one"),
            "initial": {"type": "boolean", "description": "already there when the recording started: "
                        "logged at the start, its own times kept"},
            "production_time_ns": {"type": ["integer", "null"], "description":
                                   "the write on the common time base (CLOCK_REALTIME); null: unknown"},
            "production_error_ns": {"type": ["integer", "null"], "description":
                                    "+/- bound of production_time_ns; null: unknown"},
            "age_code": {"type": "string", "enum": list(AGE_CODES), "description":
                         "synced, same_node: production time known; else why not"},
        },
        "required": ["value", "seq", "source_time_ns", "receive_time_ns", "status", "lost", "gap"],
    }
    return json.dumps(schema, indent=1).encode()


def channel_metadata(desc: SignalInfo) -> Dict[str, str]:
    """What replay checks against the node it writes to."""
    return {"ccomm.signal": desc.name, "ccomm.type": desc.type_name, "ccomm.count": str(desc.count),
            "ccomm.event": "1" if desc.is_event else "0", "ccomm.producer": desc.producer,
            "ccomm.format": FORMAT_VERSION}


def value_struct(type_name: str, count: int) -> struct.Struct:
    return struct.Struct("<%d%s" % (count, TYPE_FORMATS[type_name]))


def _number_text(type_name: str) -> Callable[[object], str]:
    if type_name == "bool":
        return lambda v: "true" if v else "false"
    if type_name in ("float", "double"):
        # repr is the shortest text that reads back as the same double (and a float32
        # widened to double reads back as the same float32); it has an 'n' only for
        # nan/inf, which JSON cannot carry.
        return lambda v: "null" if "n" in repr(v) else repr(v)
    return str


# encode(buffer, offset of the value, status, flags, seq, recv_ns, src_ns, lost, gap,
#        production time ns (-1 unknown), its error ns, age code)
MessageEncoder = Callable[[bytes, int, int, int, int, int, int, int, int, int, int, int], bytes]


def message_encoder(desc: SignalInfo) -> Tuple[struct.Struct, MessageEncoder]:
    """(value struct, MessageEncoder) for one signal: the JSON message as bytes, built
    with one format operation (the writer encodes up to 100 000 of them a second)."""
    vs = value_struct(desc.type_name, desc.count)
    number = _number_text(desc.type_name)
    floating = desc.type_name in ("float", "double")
    head = '{"value":'
    tail = ('"seq":%d,"source_time_ns":%d,"receive_time_ns":%d,"status":"%s",'
            '"fresh":%s,"safe_value":%s,"lost":%d,"gap":%d,"initial":%s,'
            '"production_time_ns":%s,"production_error_ns":%s,"age_code":"%s"}')
    unpack_from = vs.unpack_from
    scalar = desc.count == 1

    def encode(buf: bytes, off: int, status: int, flags: int, seq: int, recv: int, src: int, lost: int,
               gap: int, prod: int, prod_err: int, code: int) -> bytes:
        vals = unpack_from(buf, off)
        if scalar:
            text = number(vals[0])
        elif floating:
            text = "[" + ",".join(map(repr, vals)) + "]"
            if "n" in text:  # nan/inf somewhere: slow path, element by element
                text = "[" + ",".join(map(number, vals)) + "]"
        else:
            text = "[" + ",".join(map(number, vals)) + "]"
        return (head + text + "," + tail % (
            seq, src, recv, STATUS_NAMES[status] if status < len(STATUS_NAMES) else "?",
            "true" if status == _FRESH else "false", "true" if flags & FLAG_SAFE_VALUE else "false",
            lost, gap, "true" if flags & FLAG_INITIAL else "false",
            prod if prod >= 0 else "null", prod_err if prod >= 0 else "null",
            AGE_CODES[code] if 0 <= code < len(AGE_CODES) else "?")).encode()

    return vs, encode
