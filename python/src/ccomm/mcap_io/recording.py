# SPDX-License-Identifier: Apache-2.0
"""Reading a ccomm recording back: for replay (every value of the chosen signals, checked)
and for recovery (a complete file from one cut short)."""
from __future__ import annotations

import json
import math
import os
import struct
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Iterator, List, Optional, Set, Tuple

from mcap.records import Channel, Footer, Header, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from ..client import TYPE_FORMATS
from .schema import METADATA_NAME, SCHEMA_ENCODING, SCHEMA_PREFIX, value_struct

RECOVER_HINT = "ccomm-record --recover FILE -o FIXED.mcap keeps every intact chunk"


class RecordingError(Exception):
    """The file cannot be used; the message says why and where."""


@dataclass
class RecordedSignal:
    name: str
    type: str
    count: int
    is_event: bool
    producer: str
    # (source_time_ns, seq, value as the bytes ccomm_write takes), in file order
    values: List[Tuple[int, int, bytes]] = field(default_factory=list)

    @property
    def type_text(self) -> str:
        return self.type if self.count == 1 else f"{self.type}[{self.count}]"


@dataclass
class Recording:
    path: str
    node: str  #: the node it was recorded on
    signals: Dict[str, RecordedSignal]


def _records(path: str) -> Iterator[object]:
    """The file's records; RecordingError if it is not a readable MCAP file."""
    try:
        f = open(path, "rb")
    except OSError as e:
        raise RecordingError(f"{path}: cannot open: {e.strerror}") from None
    with f:
        if f.read(8) != b"\x89MCAP0\r\n":
            raise RecordingError(f"{path}: not an MCAP file (it does not start with the MCAP magic)")
        f.seek(0)
        yield from StreamReader(f, validate_crcs=True).records


def _damaged(path: str, e: Exception, messages: int) -> RecordingError:
    what = "ends in the middle of a record" if type(e).__name__ == "EndOfFile" else \
        f"is damaged ({type(e).__name__}: {e})"
    return RecordingError(f"{path}: {what} after {messages} messages; the file was cut short or "
                          f"corrupted ({RECOVER_HINT})")


def _channel_signal(path: str, ch: Channel, schemas: Dict[int, Schema]) -> RecordedSignal:
    md = ch.metadata
    s = schemas.get(ch.schema_id)
    if ch.message_encoding == "cdr" and "ccomm.type" in md:
        raise RecordingError(f"{path}: recorded with --profile ros2 (for ROS 2 tools): ccomm-replay "
                             "reads recordings of the default profile (ccomm-record --profile ccomm)")
    if s is None or s.encoding != SCHEMA_ENCODING or not s.name.startswith(SCHEMA_PREFIX) or \
            ch.message_encoding != "json" or "ccomm.type" not in md:
        raise RecordingError(f"{path}: channel '{ch.topic}' was not written by ccomm-record "
                             "(no ccomm schema and metadata): not a ccomm recording")
    try:
        sig = RecordedSignal(name=md.get("ccomm.signal", ch.topic), type=md["ccomm.type"],
                             count=int(md["ccomm.count"]), is_event=md.get("ccomm.event") == "1",
                             producer=md.get("ccomm.producer", ""))
    except (KeyError, ValueError):
        raise RecordingError(f"{path}: channel '{ch.topic}' has unreadable ccomm metadata {md}") from None
    if sig.type not in TYPE_FORMATS or not 1 <= sig.count <= 1 << 20:
        raise RecordingError(f"{path}: channel '{ch.topic}': unknown type {sig.type_text}")
    return sig


def _value_packer(sig: RecordedSignal) -> Callable[[object], bytes]:
    vs = value_struct(sig.type, sig.count)
    floating = sig.type in ("float", "double")
    integer = sig.type in ("int32", "uint32", "int64")

    def pack(v: object) -> bytes:
        vals = v if isinstance(v, list) else [v]
        if len(vals) != sig.count:
            raise ValueError(f"{len(vals)} values for a {sig.type_text} signal")
        if floating:
            vals = [math.nan if x is None else x for x in vals]
        elif integer and any(isinstance(x, bool) or not isinstance(x, int) for x in vals):
            raise ValueError(f"non-integer value for a {sig.type_text} signal")
        return vs.pack(*vals)

    return pack


def load(path: str, wanted: Optional[Callable[[str], bool]] = None) -> Recording:
    """Every signal of the recording, with the values of those `wanted` accepts (all by
    default; decoding a value costs more than skipping it)."""
    schemas: Dict[int, Schema] = {}
    channels: Dict[int, Optional[RecordedSignal]] = {}
    packers: Dict[int, Callable[[object], bytes]] = {}
    signals: Dict[str, RecordedSignal] = {}
    node, messages, complete = "", 0, False
    start_mono: Optional[int] = None
    it = _records(path)
    while True:
        try:
            rec = next(it)
        except StopIteration:
            break
        except RecordingError:
            raise
        except Exception as e:  # the mcap reader's errors on bad bytes are of many kinds
            raise _damaged(path, e, messages) from None
        if isinstance(rec, Schema):
            schemas[rec.id] = rec
        elif isinstance(rec, Channel) and rec.id not in channels:
            sig = _channel_signal(path, rec, schemas)
            if sig.name in signals:
                raise RecordingError(f"{path}: signal '{sig.name}' has two channels")
            signals[sig.name] = sig
            # every signal is listed (replay checks them all); values only of the wanted
            channels[rec.id] = sig if wanted is None or wanted(sig.name) else None
            packers[rec.id] = _value_packer(sig)
        elif isinstance(rec, Message):
            messages += 1
            if rec.channel_id not in channels:
                raise RecordingError(f"{path}: message {messages} is on channel {rec.channel_id}, "
                                     "which the file never declared")
            wanted_sig = channels[rec.channel_id]
            if wanted_sig is None:
                continue
            sig = wanted_sig
            try:
                m = json.loads(rec.data)
                t = int(m["source_time_ns"])
                if m.get("initial") and start_mono is not None:
                    # already there at the start: replayed at the start, not after its old gap
                    t = max(t, start_mono)
                sig.values.append((t, int(m["seq"]), packers[rec.channel_id](m["value"])))
            except (ValueError, KeyError, TypeError, struct.error) as e:
                raise RecordingError(f"{path}: message {messages} ({sig.name}, log time "
                                     f"{rec.log_time}) is not a ccomm value: {e}") from None
        elif isinstance(rec, Metadata) and rec.name == METADATA_NAME:
            node = rec.metadata.get("node", node)
            try:  # the start on the recorder's CLOCK_MONOTONIC, the clock of source times
                start_mono = int(rec.metadata["started_realtime_ns"]) - int(rec.metadata["clock_offset_ns"])
            except (KeyError, ValueError):
                start_mono = None
        elif isinstance(rec, Footer):
            complete = True
    if not complete:
        raise RecordingError(f"{path}: ends before the MCAP footer after {messages} messages: the "
                             f"recording was cut short ({RECOVER_HINT})")
    return Recording(path=path, node=node, signals=signals)


def recover(src: str, dst: str) -> Tuple[int, str]:
    """Copies every intact record of `src` into a complete file `dst`.
    Returns (messages kept, where it stopped or '' if `src` was complete)."""
    if os.path.abspath(src) == os.path.abspath(dst):
        raise RecordingError("--recover: write the result to another file than the input")
    it = _records(src)
    try:
        out = open(dst, "wb")
    except OSError as e:
        raise RecordingError(f"{dst}: cannot write: {e.strerror}") from None
    w: Any = Writer(out, compression=CompressionType.LZ4)  # its methods are not annotated
    started = False
    schema_ids: Dict[int, int] = {}
    channel_ids: Dict[int, int] = {}
    seen_meta: Set[str] = set()
    n, why = 0, ""
    while True:
        try:
            rec = next(it)
        except StopIteration:
            why = "the end of the file, before the footer" if not why else why
            break
        except RecordingError:
            out.close()
            os.unlink(dst)
            raise
        except Exception as e:
            why = str(_damaged(src, e, n))
            break
        if not started:  # the input's profile (a ros2 recording stays one)
            w.start(profile=rec.profile if isinstance(rec, Header) else "", library="ccomm-record --recover")
            started = True
        if isinstance(rec, Schema) and rec.id not in schema_ids:
            schema_ids[rec.id] = w.register_schema(rec.name, rec.encoding, rec.data)
        elif isinstance(rec, Channel) and rec.id not in channel_ids and rec.schema_id in schema_ids:
            channel_ids[rec.id] = w.register_channel(rec.topic, rec.message_encoding,
                                                     schema_ids[rec.schema_id], rec.metadata)
        elif isinstance(rec, Message) and rec.channel_id in channel_ids:
            w.add_message(channel_ids[rec.channel_id], rec.log_time, rec.data, rec.publish_time,
                          rec.sequence)
            n += 1
        elif isinstance(rec, Metadata) and rec.name not in seen_meta:
            seen_meta.add(rec.name)
            w.add_metadata(rec.name, rec.metadata)
        elif isinstance(rec, Footer):
            why = ""
            break
    if not started:
        w.start(profile="", library="ccomm-record --recover")
    w.finish()
    out.close()
    return n, why
