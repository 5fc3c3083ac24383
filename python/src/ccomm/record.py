# SPDX-License-Identifier: Apache-2.0
"""ccomm-record: records this node's signals into an MCAP file.

Two processes: this one waits for changes (ccomm_wait) and reads every selected signal
with preallocated buffers, passing each new value (a new seq) as a fixed binary record to
a writer process through a pipe; the writer (mcap_io.writer) encodes the messages and
writes the file. So the loop that must keep up with the signals does nothing else.

States the node receives are read through its history tap (signals.xml: <node
history="N">) when it has one: ccommd keeps their last N values, so a capture loop that
runs late still gets every value, or a count of those it fell too far behind for (the
`lost` field). Without the tap they are polled, and a value replaced before the loop
reads it is missed (a `gap`); the recorder says so when it starts.
"""
from __future__ import annotations

import argparse
import ctypes
import fnmatch
import gc
import json
import os
import resource
import signal
import struct
import sys
import time
from typing import Any, Callable, List, Optional, Sequence

from .mcap_io import require_mcap
from . import _native, _view
from ._tool_args import fifo_priority
from ._errors import E_CORRUPT, CcommError, error_text
from .client import Client, SignalInfo
from .realtime import realtime_setup
from .mcap_io.schema import FLAG_INITIAL, RECORD, WATERMARK_ID

EXAMPLES = """\
examples:
  ccomm-record -o run.mcap                       every signal this node holds, until ^C
  ccomm record --node planner -o run.mcap -d 10  the same through the ccomm CLI, 10 s
  ccomm-record -s 'wheel*,arm0_pos' -o wheels.mcap
  ccomm-record --rotate-size 100 -o long.mcap    long-0000.mcap, long-0001.mcap, ... of 100 MB
  ccomm-record --recover cut.mcap -o fixed.mcap  a complete file from a truncated one
  ccomm-record --profile ros2 -o run.mcap        std_msgs in CDR: ros2 bag play / rosbag2 read it

Every value of the states the node receives needs its history tap, signals.xml:
<node name="monitor" history="1024" ...> (without it they are polled, with a warning).

Open the file in Foxglove or PlotJuggler, or read it with the `mcap` Python package:
one channel per signal (topic = signal name), JSON messages with value, seq,
source_time_ns, receive_time_ns, status, lost, gap and the production time on the boards'
common (PTP) time base when known (production_time_ns, production_error_ns, age_code;
also the MCAP publish time, else the receive time). See docs/integrations/record.md.
Exit status: 0 done, 1 runtime error, 2 bad arguments or selection.
"""


def parse_args(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="ccomm-record", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Record the values of a ccomm node's signals (every value, with its seq, "
                    "source and receive time, freshness and loss) into an MCAP file.",
        epilog=EXAMPLES)
    p.add_argument("-n", "--node", help="node to attach to (default $CCOMM_NODE, else the hostname)")
    p.add_argument("-o", "--output", help="MCAP file to write (default ccomm-NODE-DATE-TIME.mcap)")
    p.add_argument("-s", "--signals", action="append", default=[], metavar="NAMES",
                   help="signals to record: names or shell patterns (wheel*), comma-separated, "
                        "repeatable (default: every signal this node produces or receives)")
    p.add_argument("-d", "--duration", type=float, default=0, metavar="SEC",
                   help="stop after SEC seconds (default: until SIGINT/SIGTERM)")
    p.add_argument("--rotate-size", type=float, default=0, metavar="MB",
                   help="start a new file (NAME-0000.mcap, NAME-0001.mcap, ...) every MB megabytes")
    p.add_argument("--rotate-seconds", type=float, default=0, metavar="SEC",
                   help="start a new file every SEC seconds")
    p.add_argument("--profile", choices=["ccomm", "ros2"], default="ccomm",
                   help="ccomm (default): JSON messages with seq, times, freshness and loss, what "
                        "ccomm-replay reads; ros2: std_msgs messages in CDR on /ccomm/SIGNAL, what "
                        "ROS 2 tools (rosbag2, ros2 bag play) read")
    p.add_argument("--compression", choices=["none", "lz4", "zstd"], default="lz4",
                   help="chunk compression (default lz4: about 3x smaller, cheap)")
    p.add_argument("--chunk-size", type=int, default=1 << 20, metavar="BYTES",
                   help="uncompressed chunk size (default 1 MiB; chunks also close every second)")
    p.add_argument("--priority", type=fifo_priority, default=0, metavar="N",
                   help="SCHED_FIFO priority of the capture loop (needs CAP_SYS_NICE); below "
                        "ccommd's. Without a history tap a state value replaced before the loop "
                        "reads it is missed (counted as a gap)")
    p.add_argument("--progress", choices=["auto", "lines", "none"], default="auto",
                   help="progress on stderr: in place on a terminal (auto), a line every 5 s, none")
    p.add_argument("-q", "--quiet", action="store_true", help="same as --progress none")
    p.add_argument("--stats-json", metavar="FILE", help="write counts per signal (values, first/last "
                                                         "seq, missed, lost) to FILE at the end")
    p.add_argument("--list", action="store_true", help="print the signals that would be recorded, exit")
    p.add_argument("--recover", metavar="FILE", help="read FILE (a recording cut short, e.g. by a "
                                                     "kill -9 or a full disk) up to its last intact "
                                                     "chunk and write a complete file to --output")
    a = p.parse_args(argv)
    if a.quiet:
        a.progress = "none"
    if a.duration < 0 or a.rotate_size < 0 or a.rotate_seconds < 0 or a.chunk_size < 1024:
        p.error("--duration, --rotate-size and --rotate-seconds must be >= 0, --chunk-size >= 1024")
    if a.recover and not a.output:
        p.error("--recover needs --output (the file to write)")
    return a


def select_signals(all_signals: List[SignalInfo], patterns: List[str], node: str) -> List[SignalInfo]:
    """The selected signals; raises ValueError with a clear message."""
    readable = [d for d in all_signals if d.readable_here]
    words = [w.strip() for arg in patterns for w in arg.split(",") if w.strip()]
    if not words:
        if not readable:
            raise ValueError(f"node '{node}' neither produces nor receives any signal: nothing to record")
        return readable
    chosen: List[SignalInfo] = []
    for w in words:
        if any(ch in w for ch in "*?["):
            hits = [d for d in readable if fnmatch.fnmatchcase(d.name, w)]
            if not hits:
                others = [d.name for d in all_signals if fnmatch.fnmatchcase(d.name, w)]
                why = (f" (it matches {', '.join(others[:5])}, which node '{node}' neither produces "
                       "nor receives)") if others else ""
                raise ValueError(f"pattern '{w}' matches no signal node '{node}' holds{why}")
        else:
            hits = [d for d in all_signals if d.name == w]
            if not hits:
                raise ValueError(f"no signal '{w}' in the configuration (`ccomm list` shows them)")
            if not hits[0].readable_here:
                raise ValueError(f"signal '{w}' is produced by '{hits[0].producer}' and not delivered "
                                 f"to node '{node}': record it on a node that consumes it")
        chosen += [d for d in hits if d not in chosen]
    return chosen


def _set_priority(prio: int) -> None:
    if prio > 0:
        err = realtime_setup(priority=prio).priority
        if err:
            print(f"record: cannot use SCHED_FIFO priority {prio} ({os.strerror(-err)}); "
                  "recording at normal priority", file=sys.stderr)


def _write_all(fd: int, data: bytearray) -> None:
    os.set_blocking(fd, True)
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _write_some(fd: int, pending: bytearray) -> None:
    """Hands the writer what the pipe takes now (fd is non-blocking): a writer that falls
    behind for a while (a loaded machine, a slow disk) delays values but never makes the
    capture loop wait and miss them; they wait here, in memory."""
    try:
        n = os.write(fd, memoryview(pending)[:1 << 20])
    except BlockingIOError:
        return
    del pending[:n]


class ReadDelay:
    """How long values waited in the segment before the capture loop read them: a state
    value that waits longer than its producer's period is replaced, and missed."""
    max_ns = 0
    over_1ms = 0


def use_history(c: Client, d: SignalInfo) -> bool:
    """A state this node receives, and the node keeps history of it (<node history=>)."""
    return not d.is_event and d.consumed_here and c.signal(d.name).history_depth > 0


def capture(c: Client, sigs: List[SignalInfo], cursors: List[Any], fd: int, duration: float, stop: List[int],
            writer_alive: Callable[[], bool], delay: ReadDelay) -> int:
    """Reads every new value of `sigs` until stopped; returns the exit status. `cursors`:
    a history cursor per signal read through the node's history tap, else None."""
    # The raw calls, bound once; pointers passed as plain addresses (see ccomm._native).
    L, handle = _native.lib(), c.handle
    read, wait, now, set_time = L.ccomm_read, L.ccomm_wait, L.ccomm_now, L.ccomm_set_time
    history_read = L.ccomm_history_read
    info = _native.Info()
    info_addr = ctypes.addressof(info)
    unpack_info = struct.Struct(_native.unpack_format(_native.Info)).unpack_from
    hinfo = _native.HistoryInfo()
    hinfo_addr = ctypes.addressof(hinfo)
    unpack_hinfo = struct.Struct(_native.unpack_format(_native.HistoryInfo)).unpack_from
    pack = RECORD.pack
    # Each value's production time on the common time base (ccomm_view_production_age),
    # with the view opened once; preallocated structs, one foreign call per value.
    try:
        ages: Optional[_view.ProductionAges] = _view.ProductionAges(handle)
    except CcommError as e:  # a ccommd without the system view: no production times
        print(f"record: no system view ({e}): production times unknown (age_code no_summary)", file=sys.stderr)
        ages = None
    production_age = L.ccomm_view_production_age_sized
    page = _native.ProductionAge()
    page_addr, page_size = ctypes.addressof(page), ctypes.sizeof(page)
    unpack_page = struct.Struct(_native.unpack_format(_native.ProductionAge)).unpack_from
    hist_info = _native.Info()  # a history read's seq and source time, for the age call
    hist_info_addr = ctypes.addressof(hist_info)

    def production(sid: int, info_at: int) -> Any:
        # (production time or -1, its error or -1, age code); an error gives "no_summary"
        view_ptr = ages.raw if ages is not None else None
        if view_ptr is None or production_age(view_ptr, sid, info_at, page_addr, page_size) != 0:
            return -1, -1, 5
        code, known, _age, err, ptime = unpack_page(page)
        return (ptime, err, code) if known else (-1, -1, code)

    def initial_status(sid: int, size: int, seq: int) -> int:
        # The status a read gives now for the value a history cursor starts at (the newest
        # kept): stale when it is older than stale_after_ms. Read into a scratch buffer (a
        # stale read returns the safe value, the history the value itself); fresh if a newer
        # value arrived in between.
        scratch = (ctypes.c_ubyte * size)()
        r = read(handle, sid, ctypes.addressof(scratch), size, info_addr)
        st, _flags, rseq, _age, _src, _lost = unpack_info(info)
        return int(st) if r in (0, 1) and rseq == seq else 0

    bufs = [(ctypes.c_ubyte * d.value_bytes)() for d in sigs]
    # A history cursor per received state when the node keeps history (from the newest
    # value kept: what polling would have read first), else None.
    # (index, id, buffer address, size, buffer view, is event, history cursor address or 0,
    # produced on this node)
    items = [(i, d.id, ctypes.addressof(b), d.value_bytes, memoryview(b).cast("B"), d.is_event,
              ctypes.addressof(cur) if cur is not None else 0, d.produced_here)
             for i, (d, b, cur) in enumerate(zip(sigs, bufs, cursors))]
    last_seq = [0] * len(sigs)
    first = [True] * len(sigs)  # no value of the signal read yet
    # History-read signals: the cursor's overrun at the previous value, and the values lost
    # before reaching this node so far. A jump in seq is either values the cursor fell too
    # far behind for (its overrun grew: the recorder missed them, the `gap` says so) or
    # values that never reached the node (added to `lost`): exact, per value.
    last_overrun = [0] * len(sigs)
    lost_so_far = [0] * len(sigs)
    out = bytearray()
    pending = bytearray()
    os.set_blocking(fd, False)
    warned = False
    start = now()
    end = start + int(duration * 1e9) if duration > 0 else 0
    last_send = last_check = start
    while not stop:
        wait(handle, 100)
        t = now()
        set_time(handle, t)  # ages against t: the arrival time is t - age, exactly, if before t
        for i, sid, addr, size, view, event, cursor, local in items:
            if cursor:  # every value ccommd stored, in order (see last_overrun above)
                while True:
                    r = history_read(handle, sid, cursor, addr, size, hinfo_addr)
                    if r == E_CORRUPT:  # a damaged copy: skipped, counted in the overrun
                        continue
                    if r < 0:
                        print(f"record: reading {sigs[i].name} failed: {error_text(r)}", file=sys.stderr)
                        return 1
                    if r != 0:  # EMPTY: caught up
                        break
                    seq, src, recv, overrun, lost = unpack_hinfo(hinfo)
                    prev = last_seq[i]
                    initial = prev == 0 and recv < start
                    age = t - recv
                    if not initial:  # a value from before the start did not wait for the capture
                        if age > delay.max_ns:
                            delay.max_ns = age
                        if age >= 1_000_000:
                            delay.over_1ms += 1
                    if prev == 0:
                        lost_so_far[i] = lost  # ccommd's count when recording starts
                    elif seq > prev + 1:
                        lost_so_far[i] += max(0, seq - prev - 1 - (overrun - last_overrun[i]))
                    last_seq[i], last_overrun[i] = seq, overrun
                    hist_info.seq, hist_info.source_time_ns = seq, src
                    status = 0  # each value the history kept was fresh when ccommd stored it
                    if initial:  # ... but one from before the start: as a read says now
                        status = initial_status(sid, size, seq)
                    out += pack(sid, status, FLAG_INITIAL if initial else 0, seq, recv, src,
                                lost_so_far[i], *production(sid, hist_info_addr))
                    out += view
                continue
            while True:
                r = read(handle, sid, addr, size, info_addr)
                if r < 0:
                    print(f"record: reading {sigs[i].name} failed: {error_text(r)}", file=sys.stderr)
                    return 1
                if r >= 2:  # NEVER (no value yet) or EMPTY (no new event)
                    break
                status, flags, seq, age, src, lost = unpack_info(info)
                if seq != last_seq[i]:
                    last_seq[i] = seq
                    # The library stamps a value's arrival; a read gives its age against t,
                    # 0 for one that arrived after t (during this pass). A value written on
                    # this node arrived when it was written: its source time, exactly. One
                    # received that arrived during the pass: between t and now, so now
                    # (never before its arrival, at most the pass late).
                    recv = src if local else (t - age if age > 0 else now())
                    initial = False
                    if not event and first[i]:  # a state's value already there at the start
                        first[i] = False
                        initial = recv < start
                        if initial:
                            flags |= FLAG_INITIAL
                    if not initial:  # a value from before the start did not wait for the capture
                        if age > delay.max_ns:
                            delay.max_ns = age
                        if age >= 1_000_000:
                            delay.over_1ms += 1
                    out += pack(sid, status, flags, seq, recv, src, lost, *production(sid, info_addr))
                    out += view
                if not event:
                    break
        if len(out) >= 65536 or ((out or pending) and t - last_send >= 20_000_000):
            # every value received up to t has now been read: the writer may write those
            out += pack(WATERMARK_ID, 0, 0, 0, t, 0, 0, -1, -1, 0)
            pending += out
            out.clear()
            _write_some(fd, pending)
            last_send = t
        if t - last_check >= 1_000_000_000:
            last_check = t
            if ages is not None:
                ages.follow(time.monotonic())  # a restarted ccommd's new view
            if not writer_alive():
                return 1
            if len(pending) > 256 << 20 and not warned:
                warned = True
                print("record: warning: the writer process is more than 256 MB behind (disk or CPU "
                      "too slow); values wait in memory", file=sys.stderr)
        if end and t >= end:
            break
    set_time(handle, 0)
    pending += out
    _write_all(fd, pending)
    return 0


def record(a: argparse.Namespace) -> int:
    from .mcap_io.writer import WriterOptions, run_writer
    try:
        c = Client(a.node, check_daemon=False)
        node = c.node
        all_signals = c.signals()
    except (CcommError, OSError) as e:
        print(f"record: {e}", file=sys.stderr)
        return 1
    try:
        sigs = select_signals(all_signals, a.signals, node)
    except ValueError as e:
        print(f"record: {e}", file=sys.stderr)
        return 2
    if a.list:
        for d in sigs:
            print(f"{d.name}\t{d.type_text}\t{'event' if d.is_event else 'state'}\tfrom {d.producer}")
        return 0
    if not c.daemon_alive:
        print(f"record: warning: ccommd of node '{node}' shows no heartbeat; recording what "
              "the segment holds", file=sys.stderr)
    polled = [d.name for d in sigs if not d.is_event and d.consumed_here and not use_history(c, d)]
    if polled:
        print(f"record: warning: node '{node}' keeps no history of the states it receives "
              f"({len(polled)} selected, e.g. {polled[0]}): they are polled, and a value replaced before "
              f"the recorder reads it is missed (a gap in the file). Give the node a history tap in "
              f'signals.xml (<node name="{node}" history="1024" ...>) to record every value.',
              file=sys.stderr)
    output = a.output or time.strftime(f"ccomm-{node}-%Y%m%d-%H%M%S.mcap")
    offset = time.clock_gettime_ns(time.CLOCK_REALTIME) - time.clock_gettime_ns(time.CLOCK_MONOTONIC)
    opts = WriterOptions(output=output, signals=sigs, node=node, compression=a.compression,
                         chunk_size=a.chunk_size, rotate_bytes=int(a.rotate_size * 1e6),
                         rotate_seconds=a.rotate_seconds, clock_offset_ns=offset,
                         progress=a.progress, stats_json=a.stats_json, started_ns=time.time_ns(),
                         profile=a.profile)
    # History cursors from the newest value kept (what polling would read first), made
    # before the start message: every value that arrives after it is recorded.
    cursors = [c.signal(d.name).history(1).cursor if use_history(c, d) else None for d in sigs]
    rfd, wfd = os.pipe()
    try:  # room for about half a second of values at 100 000 values/s
        import fcntl
        fcntl.fcntl(wfd, 1031, 1 << 20)  # F_SETPIPE_SZ
    except OSError:
        pass
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        os.close(wfd)
        code = 1
        # The writer keeps the normal policy: it may use most of a core, and as a real-time
        # task it would eat into the real-time budget of the CPU it shares with ccommd and
        # the capture (the kernel throttles all of them when that runs out). It never
        # delays the capture: values wait in the capture's memory when it falls behind.
        try:
            code = run_writer(rfd, opts)
        finally:
            sys.stderr.flush()
            os._exit(code)
    os.close(rfd)
    stop: List[int] = []
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, lambda *_: stop.append(1))
    if a.progress != "none":
        print(f"record: node {node}, {len(sigs)} signals -> {output} (^C to stop)", file=sys.stderr)
    _set_priority(a.priority)
    gc.disable()  # the loop makes no cycles; a collection pause could miss a value
    ended: List[int] = []
    delay = ReadDelay()

    def writer_alive() -> bool:
        if not ended:
            done, wstatus = os.waitpid(pid, os.WNOHANG)
            if done:
                ended.append(os.waitstatus_to_exitcode(wstatus))
        return not ended

    try:
        code = capture(c, sigs, cursors, wfd, a.duration, stop, writer_alive, delay)
    except BrokenPipeError:
        code = 1
    finally:
        os.close(wfd)
        c.close()
    if not ended:
        ended.append(os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]))
    wcode = ended[0]
    if wcode < 0:  # killed: it said nothing, and the file has no footer
        print(f"record: the writer process was killed ({signal.Signals(-wcode).name}): the file it was "
              "writing holds every chunk closed so far but no footer; ccomm-record --recover FILE "
              "-o FIXED.mcap makes a complete file of it", file=sys.stderr)
        return 1
    if wcode != 0:
        print(f"record: the writer process failed (exit {wcode}); see its message above",
              file=sys.stderr)
        return 1
    _report_capture(a, delay)
    return code


def _report_capture(a: argparse.Namespace, delay: ReadDelay) -> None:
    """CPU seconds of the capture loop and of the writer, and the read delays, into
    --stats-json and on stderr."""
    me, child = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = {"cpu_capture_s": round(me.ru_utime + me.ru_stime, 3),
           "cpu_writer_s": round(child.ru_utime + child.ru_stime, 3),
           "read_delay_max_ns": delay.max_ns, "reads_delayed_over_1ms": delay.over_1ms}
    if a.stats_json:
        try:
            with open(a.stats_json) as f:
                s = json.load(f)
            s.update(cpu)
            with open(a.stats_json, "w") as f:
                json.dump(s, f, indent=1)
        except (OSError, ValueError) as e:
            print(f"record: cannot update {a.stats_json}: {e}", file=sys.stderr)
    if a.progress != "none":
        print(f"record: CPU time: capture {cpu['cpu_capture_s']} s, writer {cpu['cpu_writer_s']} s; "
              f"values read up to {delay.max_ns / 1e6:.2f} ms after they arrived, "
              f"{delay.over_1ms} of them 1 ms or more", file=sys.stderr)


def main(argv: Optional[Sequence[str]] = None) -> int:
    a = parse_args(argv)
    if not require_mcap("record"):
        return 1
    if a.recover:
        from .mcap_io.recording import RecordingError, recover
        try:
            n, why = recover(a.recover, a.output)
        except RecordingError as e:
            print(f"record: {e}", file=sys.stderr)
            return 1
        print(f"record: {a.output}: {n} messages recovered from {a.recover}" +
              (f"; stopped at {why}" if why else " (the file was complete)"), file=sys.stderr)
        return 0
    return record(a)


if __name__ == "__main__":
    sys.exit(main())
