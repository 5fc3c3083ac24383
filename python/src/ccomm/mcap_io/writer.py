# SPDX-License-Identifier: Apache-2.0
"""The recorder's writer process: captured records in (a pipe), MCAP files out.

It runs apart from the capture loop so that encoding and disk writes never delay a read
(a state signal read late may already hold the next value). It ends when the pipe
closes: after the capture loop's clean stop, and also when the capture process was
killed (kill -9), so the file is complete in both cases. Killed itself, it leaves a file
that holds every chunk written so far (a chunk is closed at least once a second);
`ccomm-record --recover` makes a complete file of it.
"""
from __future__ import annotations

import heapq
import json
import os
import select
import signal
import sys
import time
from dataclasses import dataclass, field
from typing import IO, Any, Dict, List, Optional, Tuple

from mcap.writer import CompressionType, Writer

from ..client import SignalInfo
from . import ros2_profile
from .schema import (AGE_CODES, FLAG_INITIAL, FORMAT_VERSION, MESSAGE_ENCODING, METADATA_NAME, RECORD,
                     SCHEMA_ENCODING, WATERMARK_ID, channel_metadata, json_schema, message_encoder, schema_name)

SAME_NODE = AGE_CODES.index("same_node")  #: age code of a value written on the recording node
HOLD_MIN_NS = 20_000_000  #: messages held behind the capture's watermark, at least
HOLD_MAX_NS = 2_000_000_000  #: and at most (memory: 2 s of every signal)

COMPRESSION = {"none": CompressionType.NONE, "lz4": CompressionType.LZ4,
               "zstd": CompressionType.ZSTD}


@dataclass
class WriterOptions:
    output: str
    signals: List[SignalInfo]
    node: str
    compression: str = "lz4"
    chunk_size: int = 1 << 20
    rotate_bytes: int = 0  #: 0: no rotation by size
    rotate_seconds: float = 0  #: 0: no rotation by time
    clock_offset_ns: int = 0  #: CLOCK_REALTIME - CLOCK_MONOTONIC at the start
    progress: str = "auto"  #: auto (a line in place on a terminal), lines, none
    stats_json: Optional[str] = None
    started_ns: int = 0
    profile: str = "ccomm"  #: ccomm (JSON, what replay reads) or ros2 (std_msgs in CDR, ros2_profile.py)


@dataclass
class SignalStats:
    values: int = 0
    first_seq: int = 0
    last_seq: int = 0
    gaps: int = 0  #: values missed by the recorder (jumps in seq that ccomm did not count lost)
    first_lost: int = -1
    last_lost: int = 0


@dataclass
class FileSet:
    """The files written so far (several with rotation)."""
    paths: List[str] = field(default_factory=list)
    bytes_done: int = 0  #: sizes of the closed files


def rotated_name(output: str, index: int) -> str:
    stem, ext = os.path.splitext(output)
    return f"{stem}-{index:04d}{ext or '.mcap'}"


class RecordingWriter:
    def __init__(self, o: WriterOptions) -> None:
        self.o = o
        self.by_id: Dict[int, SignalInfo] = {d.id: d for d in o.signals}
        encoder = ros2_profile.message_encoder if o.profile == ros2_profile.PROFILE else message_encoder
        self.encoders = {d.id: encoder(d)[1] for d in o.signals}
        self.value_bytes = {d.id: d.value_bytes for d in o.signals}
        self.stats = {d.id: SignalStats() for d in o.signals}
        self.files = FileSet()
        self.values = 0
        self.stream: Optional[IO[bytes]] = None
        self.mcap: Any = None  # mcap.writer.Writer (its methods are not annotated)
        self.channel: Dict[int, int] = {}
        self.file_opened = 0.0
        self.rotating = o.rotate_bytes > 0 or o.rotate_seconds > 0
        # messages not yet written: (log time, arrival order, channel, data, publish time, seq)
        self.held: List[Tuple[int, int, int, bytes, int, int]] = []
        self.order = 0
        # ccommd stamps a received value with the time its frame arrived, which is before
        # it stores it (longer when the frame waited in its socket: peer_clock.h). So a
        # value can surface after a watermark later than its stamp; the writer keeps
        # `hold_ns` behind the watermark and widens it to twice the worst such lateness.
        self.hold_ns = HOLD_MIN_NS
        self.last_written = 0  #: log time of the newest message written (never goes back)
        self.late = 0  #: messages that came after later ones were written: logged at that later time
        self.late_max_ns = 0  #: the most such a message came late
        self.watermark = 0  #: newest watermark from the capture

    # ---- files ---------------------------------------------------------------------
    def _open(self) -> None:
        path = rotated_name(self.o.output, len(self.files.paths)) if self.rotating else self.o.output
        self.stream = open(path, "wb")
        self.files.paths.append(path)
        w = Writer(self.stream, chunk_size=self.o.chunk_size, compression=COMPRESSION[self.o.compression])
        ros2 = self.o.profile == ros2_profile.PROFILE
        w.start(profile=ros2_profile.PROFILE if ros2 else "", library="ccomm-record")
        schemas: Dict[str, int] = {}
        self.channel = {}
        for d in self.o.signals:
            if ros2:
                name, data, topic = ros2_profile.schema_and_channel(d)
                if name not in schemas:
                    schemas[name] = w.register_schema(name, ros2_profile.SCHEMA_ENCODING, data)
                meta = dict(channel_metadata(d), offered_qos_profiles=ros2_profile.offered_qos_profiles(d))
                self.channel[d.id] = w.register_channel(topic, ros2_profile.MESSAGE_ENCODING, schemas[name], meta)
                continue
            name = schema_name(d)
            if name not in schemas:
                schemas[name] = w.register_schema(name, SCHEMA_ENCODING, json_schema(d))
            self.channel[d.id] = w.register_channel(d.name, MESSAGE_ENCODING, schemas[name],
                                                    channel_metadata(d))
        w.add_metadata(METADATA_NAME, {
            "format": FORMAT_VERSION, "profile": self.o.profile, "node": self.o.node,
            "clock_offset_ns": str(self.o.clock_offset_ns),
            "started_realtime_ns": str(self.o.started_ns),
            "file_index": str(len(self.files.paths) - 1),
            "signals": ",".join(d.name for d in self.o.signals)})
        self.mcap = w
        self.file_opened = time.monotonic()

    def _close(self, drain: bool = True) -> None:
        """Ends the file; with `drain` (the recording ends) after every held message."""
        if self.mcap is not None and self.stream is not None:
            if drain:
                self._write_held(1 << 63)
            self.mcap.finish()
            self.stream.close()
            self.files.bytes_done += os.path.getsize(self.files.paths[-1])
        self.mcap = None
        self.stream = None

    def _size(self) -> int:
        return self.stream.tell() if self.stream is not None else 0

    def maybe_rotate(self) -> None:
        if not self.rotating or self.mcap is None:
            return
        if (self.o.rotate_bytes and self._size() >= self.o.rotate_bytes) or \
           (self.o.rotate_seconds and time.monotonic() - self.file_opened >= self.o.rotate_seconds):
            self._close(drain=False)  # held values go into the next file, still in order
            self._open()

    def total_bytes(self) -> int:
        return self.files.bytes_done + self._size()

    # ---- records -------------------------------------------------------------------
    def add(self, buf: bytearray) -> int:
        """Writes the complete records at the start of `buf`; returns the bytes used."""
        assert self.mcap is not None
        add_message, channel, encoders = self.mcap.add_message, self.channel, self.encoders
        vbytes, stats, offset = self.value_bytes, self.stats, self.o.clock_offset_ns
        unpack_from, head = RECORD.unpack_from, RECORD.size
        pos, end, n = 0, len(buf), 0
        held, started = self.held, self.o.started_ns
        while pos + head <= end:
            sid, status, flags, seq, recv, src, lost, prod, prod_err, code = unpack_from(buf, pos)
            if sid == WATERMARK_ID:  # every value stored by ccommd up to recv has been captured
                self.watermark = recv + offset
                self._write_held(self.watermark - self.hold_ns)
                pos += head
                continue
            size = vbytes[sid]
            if pos + head + size > end:
                break
            st = stats[sid]
            gap = seq - st.last_seq - 1 if st.values and seq > st.last_seq else 0
            if st.values == 0:
                st.first_seq, st.first_lost = seq, lost
            elif gap:
                # ccomm counted lost values itself (a network gap): those the recorder could
                # not have seen; the rest of the jump it missed (read too late)
                st.gaps += max(0, gap - (lost - st.last_lost))
            st.values += 1
            st.last_seq, st.last_lost = seq, lost
            data = encoders[sid](buf, pos + head, status, flags, seq, recv, src, lost, gap, prod, prod_err, code)
            # an initial value (received before the start) is logged at the start
            log_time = started if flags & FLAG_INITIAL else recv + offset
            if not flags & FLAG_INITIAL and log_time < self.watermark - self.hold_ns // 2:
                # stored by ccommd well after its stamp: hold longer from now on
                self.hold_ns = min(HOLD_MAX_NS, max(self.hold_ns, 2 * (self.watermark - log_time)))
            # publish time: the production on the common time base, else the arrival here
            publish_time = prod if prod >= 0 else recv + offset
            if code == SAME_NODE and prod >= 0 and not flags & FLAG_INITIAL:
                # written on this node: its arrival is the write, one instant; logged at
                # the production time too (recv + offset, the start's clock offset, can
                # differ from it by the realtime clock's slew since: then a log time
                # before the publish time, a receive before the write)
                log_time = publish_time
            heapq.heappush(held, (log_time, self.order, channel[sid], data, publish_time, seq & 0xFFFFFFFF))
            self.order += 1
            pos += head + size
            n += 1
        self.values += n
        return pos

    def _write_held(self, upto: int) -> None:
        """Writes the held messages logged at or before `upto`, in log-time order (values
        of different signals are captured in turns, so they come out of order by up to
        one turn; the watermark says when no earlier one can still come)."""
        held, add_message = self.held, self.mcap.add_message
        while held and held[0][0] <= upto:
            log_time, _, channel, data, publish_time, sequence = heapq.heappop(held)
            if log_time < self.last_written:
                # Came later than the hold allowed: logged at the newest time written, so
                # the file stays in log-time order (its receive time is in the message).
                self.late += 1
                self.late_max_ns = max(self.late_max_ns, self.last_written - log_time)
                log_time = self.last_written
            self.last_written = log_time
            add_message(channel, log_time, data, publish_time, sequence)

    def flush(self) -> None:
        if self.mcap is not None:
            self.mcap.flush()  # closes the chunk: what a kill -9 of this process keeps

    def lost_total(self) -> int:
        return sum(s.gaps for s in self.stats.values())

    def ccomm_lost_total(self) -> int:
        return sum(s.last_lost - s.first_lost for s in self.stats.values() if s.values)

    def summary(self, seconds: float) -> Dict[str, Any]:
        return {
            "node": self.o.node, "files": self.files.paths, "seconds": round(seconds, 3),
            "values": self.values, "bytes": self.total_bytes(),
            "values_per_s": round(self.values / seconds, 1) if seconds > 0 else 0.0,
            "recorder_missed": self.lost_total(), "ccomm_lost": self.ccomm_lost_total(),
            "logged_late": self.late, "logged_late_max_ms": round(self.late_max_ns / 1e6, 3),
            "hold_ms": round(self.hold_ns / 1e6, 3),
            "signals": {self.by_id[i].name: {"values": s.values, "first_seq": s.first_seq,
                                             "last_seq": s.last_seq, "missed": s.gaps,
                                             "lost": (s.last_lost - s.first_lost) if s.values else 0}
                        for i, s in self.stats.items()},
        }


def _progress_line(w: RecordingWriter, elapsed: float, rate: float) -> str:
    return (f"record: {elapsed:7.1f} s  {w.values:10d} values  {rate:9.0f} values/s  "
            f"{w.total_bytes() / 1e6:8.2f} MB  missed {w.lost_total()}  lost {w.ccomm_lost_total()}")


def run_writer(fd: int, o: WriterOptions) -> int:
    """The writer process's main: returns its exit status."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the terminal's ^C is the capture's to handle
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    w = RecordingWriter(o)
    try:
        w._open()
    except OSError as e:
        print(f"record: cannot write {e.filename}: {e.strerror}", file=sys.stderr)
        return 1
    mode = o.progress
    if mode == "auto":
        mode = "tty" if sys.stderr.isatty() else "lines"
    every = 1.0 if mode == "tty" else 5.0
    buf = bytearray()
    t0 = last_flush = last_report = time.monotonic()
    reported_values = 0
    while not stop:
        ready, _, _ = select.select([fd], [], [], 0.2)
        if ready:
            data = os.read(fd, 1 << 20)
            if not data:
                break
            buf += data
            used = w.add(buf)
            del buf[:used]
            w.maybe_rotate()
        now = time.monotonic()
        if now - last_flush >= 1.0:
            w.flush()
            last_flush = now
        if mode != "none" and now - last_report >= every:
            rate = (w.values - reported_values) / (now - last_report)
            line = _progress_line(w, now - t0, rate)
            print("\r" + line if mode == "tty" else line, end="" if mode == "tty" else "\n",
                  file=sys.stderr, flush=True)
            last_report, reported_values = now, w.values
    if buf:
        print(f"record: {len(buf)} bytes of an incomplete record at the end dropped "
              "(the capture process died mid-write)", file=sys.stderr)
    w._close()
    elapsed = time.monotonic() - t0
    s = w.summary(elapsed)
    if mode == "tty":
        print(file=sys.stderr)
    if mode != "none":
        print(f"record: {', '.join(s['files'])}: {s['values']} values of {len(o.signals)} signals in "
              f"{elapsed:.1f} s ({s['values_per_s']:.0f}/s), {s['bytes'] / 1e6:.2f} MB, missed by the "
              f"recorder {s['recorder_missed']}, lost in ccomm {s['ccomm_lost']}", file=sys.stderr)
        if s["logged_late"]:
            print(f"record: {s['logged_late']} values stored by ccommd more than the reorder hold after "
                  f"their receive time (at most {s['logged_late_max_ms']} ms): logged at the newest log time "
                  f"then (their receive_time_ns is exact); the hold grew to {s['hold_ms']} ms", file=sys.stderr)
    if o.stats_json:
        try:
            with open(o.stats_json, "w") as f:
                json.dump(s, f, indent=1)
        except OSError as e:  # said here: the process ends in os._exit, which drops a traceback
            print(f"record: cannot write {o.stats_json}: {e.strerror}", file=sys.stderr)
            return 1
    return 0
