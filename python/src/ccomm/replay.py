# SPDX-License-Identifier: Apache-2.0
"""ccomm-replay: writes the values of an MCAP recording back into the signals this node
produces, at the original timing (the producer's write times), for hardware-in-the-loop
regression. Values written at the same moment (one control cycle) leave in one frame."""
from __future__ import annotations

import argparse
import array
import ctypes
import fnmatch
import gc
import json
import os
import signal
import sys
import time
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Sequence, Tuple

from .mcap_io import require_mcap
from . import _native
from ._tool_args import fifo_priority
from ._errors import E_BUSY, E_FULL, CcommError, error
from .client import Client, SignalInfo
from .realtime import realtime_setup

if TYPE_CHECKING:
    from .mcap_io.recording import Recording

try:
    import resource  # POSIX only: the page faults and preemptions of a replay
except ImportError:  # Windows
    resource = None  # type: ignore[assignment]

EXAMPLES = """\
examples:
  ccomm-replay run.mcap                  every recorded signal this node produces, as recorded
  ccomm replay --node control run.mcap   the same through the ccomm CLI
  ccomm-replay --rate 2 --loop run.mcap  twice as fast, over and over until ^C
  ccomm-replay -s 'wheel*' run.mcap      only these signals (an error if one is not produced here)

Signals of the recording that other nodes produce are skipped (and listed) unless named
in --signals, where they are an error; so are signals missing from this node's
configuration or whose type or size changed. Exit status: 0 done, 1 runtime error,
2 the recording does not fit this node (nothing is written then).
"""


def parse_args(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="ccomm-replay", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Write the values of a ccomm-record MCAP file into the signals this node "
                    "produces, at the recorded timing.", epilog=EXAMPLES)
    p.add_argument("file", metavar="FILE.mcap", help="recording made by ccomm-record")
    p.add_argument("-n", "--node", help="node to attach to (default $CCOMM_NODE, else the hostname)")
    p.add_argument("-s", "--signals", action="append", default=[], metavar="NAMES",
                   help="signals to replay: names or shell patterns, comma-separated, repeatable "
                        "(default: every recorded signal this node produces)")
    p.add_argument("-r", "--rate", type=float, default=1.0,
                   help="speed factor: 2 = twice as fast (default 1: the recorded timing)")
    p.add_argument("--loop", action="store_true", help="start again at the end, until SIGINT/SIGTERM")
    p.add_argument("--priority", type=fifo_priority, default=0, metavar="N",
                   help="SCHED_FIFO priority (needs CAP_SYS_NICE): steadier timing")
    p.add_argument("--check", action="store_true",
                   help="check that the recording fits this node and print what would be replayed")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress or summary on stderr")
    p.add_argument("--stats-json", metavar="FILE",
                   help="write values written and timing error (ns: p50, p99, max) to FILE")
    a = p.parse_args(argv)
    if not a.rate > 0:
        p.error("--rate must be > 0")
    return a


class Refusal(Exception):
    """The recording does not fit this node: exit 2, nothing written."""


def plan(rec: "Recording", descs: List[SignalInfo], patterns: List[str],
         node: str) -> Tuple[List[Tuple[SignalInfo, str]], List[str]]:
    """(signals to replay as (desc, recorded name), notes about skipped ones)."""
    words = [w.strip() for arg in patterns for w in arg.split(",") if w.strip()]
    by_name: Dict[str, SignalInfo] = {d.name: d for d in descs}
    named = {w for w in words if not any(c in w for c in "*?[")}
    for w in named:
        if w not in rec.signals:
            raise Refusal(f"signal '{w}' is not in {rec.path} (it has {len(rec.signals)} signals)")
    for w in words:
        if w not in named and not any(fnmatch.fnmatchcase(n, w) for n in rec.signals):
            raise Refusal(f"pattern '{w}' matches no signal of {rec.path}")
    chosen, notes = [], []
    for name, rs in rec.signals.items():
        if words and not any(fnmatch.fnmatchcase(name, w) for w in words):
            continue
        d = by_name.get(name)
        if d is None:
            raise Refusal(f"signal '{name}' of {rec.path} does not exist on node '{node}': the "
                          "recording is of another configuration (select signals with --signals)")
        if d.type_name != rs.type or d.count != rs.count or d.is_event != rs.is_event:
            def kind(event: bool) -> str:
                return "event" if event else "state"
            raise Refusal(f"signal '{name}' was recorded as {kind(rs.is_event)} {rs.type_text}, but "
                          f"node '{node}' has it as {kind(d.is_event)} {d.type_text}: the "
                          "configuration changed since the recording")
        if not d.produced_here:
            if name in named:
                raise Refusal(f"signal '{name}' is produced by '{d.producer}', not by node '{node}': "
                              "replay it there")
            notes.append(name)
            continue
        chosen.append((d, name))
    if not chosen:
        raise Refusal(f"node '{node}' produces none of the signals to replay from {rec.path} "
                      f"(they come from {', '.join(sorted({rec.signals[n].producer for n in notes}))})")
    return chosen, notes


def _percentile(sorted_vals: List[int], q: float) -> int:
    if not sorted_vals:
        return 0
    return sorted_vals[min(len(sorted_vals) - 1, int(q * len(sorted_vals)))]


def replay(c: Client, timeline: List[Tuple[int, int, int, bytes]], rate: float, loop: bool,
           stop: List[int], quiet: bool) -> Tuple[int, List[int], Dict[str, Any]]:
    """Writes the timeline ((source time, seq, signal id, value)); returns (values written,
    lateness of each write in ns, what made it late: waits for ccommd, full-ring retries)."""
    # The raw calls, bound once; pointers passed as plain addresses (see ccomm._native).
    L, handle, now = _native.lib(), c.handle, time.monotonic_ns
    write = L.ccomm_write
    # A state is sent as its newest value: a step flushed before ccommd took the previous
    # one would replace it unsent (counted `coalesced` on this node). So each flush first
    # waits, bounded, until ccommd has taken the previous step: its `tx` counter of a
    # signal of that step moved. Costs two stats reads a step; waits only when replay runs
    # late and steps follow each other within ccommd's wake-up time.
    stats = _native.SignalStats()
    stats_addr = ctypes.addressof(stats)
    get_stats, raw_flush = L.ccomm_get_signal_stats_sized, L.ccomm_flush
    stats_size = ctypes.sizeof(stats)
    probe = [-1, 0]  # a signal of the last flushed step, its tx before that flush

    def tx_of(sid: int) -> int:
        get_stats(handle, sid, stats_addr, stats_size)
        return int(stats.tx)

    # No probe for a signal ccommd never sends: one no other node consumes (its tx never
    # moves: each of its steps waited out the 10 ms bound), nor one it did not send within
    # the bound.
    no_tx: "set[int]" = {d.id for d in c.signals() if not d.forwarded}

    def flush(hd: int) -> None:
        if probe[0] >= 0:
            began = now()
            deadline = began + 10_000_000
            while tx_of(probe[0]) <= probe[1]:
                if now() >= deadline:
                    no_tx.add(probe[0])
                    break
                time.sleep(0.00005)
            waited = now() - began
            if waited >= 1_000_000:  # how much of the lateness is ccommd's (the report says)
                waits[0] += 1
                waits[1] += waited
            probe[0] = -1
        if last_sid[0] >= 0 and last_sid[0] not in no_tx:
            probe[0], probe[1] = last_sid[0], tx_of(last_sid[0])
            last_sid[0] = -1
        raw_flush(hd)

    last_sid = [-1]  # a signal written since the last flush
    retries = [0]  # writes retried after 1 ms because an event ring was full
    waits = [0, 0]  # flushes that waited 1 ms or more for ccommd to take the previous step, their total ns
    t0 = timeline[0][0]
    span = timeline[-1][0] - t0
    # One slot per write, allocated before the timing starts: nothing grows in the loop
    # (with --loop, the slots of the pass before are overwritten: the stats are of the last).
    late = array.array("q", bytes(8 * len(timeline)))
    written = 0
    # Signals written since the last flush: a second value of one of them starts a new
    # step (flush first), so a replay that runs late still hands ccommd every value in its
    # own step instead of replacing one with the next (a gap in the stream).
    in_step = bytearray(max(sid for _t, _s, sid, _d in timeline) + 1)
    start = now() + 20_000_000
    last_report = now()
    while not stop:
        for t, _seq, sid, data in timeline:
            target = start + int((t - t0) / rate)
            n = now()
            if target > n:
                flush(handle)  # the values due before now leave together
                in_step[:] = bytes(len(in_step))
                time.sleep((target - n) / 1e9)  # clock_nanosleep: about 60 us late at most, idle
                if stop:
                    break
            elif in_step[sid]:
                flush(handle)
                in_step[:] = bytes(len(in_step))
            in_step[sid] = 1
            if sid not in no_tx:
                last_sid[0] = sid
            r = write(handle, sid, data, len(data))
            tries = 0
            while r in (E_FULL, E_BUSY) and tries < 1000 and not stop:
                flush(handle)  # an event ring is full: give ccommd a moment
                time.sleep(0.001)
                tries += 1
                r = write(handle, sid, data, len(data))
            if tries:
                retries[0] += tries
            if r < 0:
                raise error(r, f"writing signal {sid} failed")
            late[written % len(late)] = now() - target
            written += 1
            if not quiet and now() - last_report >= 1_000_000_000:
                last_report = now()
                tty = sys.stderr.isatty()  # in place on a terminal, else a line each
                print(("\r" if tty else "") + f"replay: {(t - t0) / 1e9:7.1f} / {span / 1e9:.1f} s  {written} values",
                      end="" if tty else "\n", file=sys.stderr, flush=True)
        flush(handle)
        if not loop:
            break
        start += int(span / rate) + int((span / max(len(timeline) - 1, 1)) / rate)
    return written, list(late[:min(written, len(late))]), {"waits_over_1ms": waits[0], "waited_ms": round(waits[1] / 1e6, 3),
                           "full_retries": retries[0]}


def _usage() -> Dict[str, int]:
    if resource is None:
        return {"major_faults": 0, "minor_faults": 0, "preempted": 0}
    u = resource.getrusage(resource.RUSAGE_SELF)
    return {"major_faults": u.ru_majflt, "minor_faults": u.ru_minflt, "preempted": u.ru_nivcsw}


def main(argv: Optional[Sequence[str]] = None) -> int:
    a = parse_args(argv)
    if not require_mcap("replay"):
        return 1
    from .mcap_io.recording import RecordingError, load
    words = [w.strip() for arg in a.signals for w in arg.split(",") if w.strip()]
    try:
        c = Client(a.node, batch=True, check_daemon=False)
        node = c.node
        descs = c.signals()
    except (CcommError, OSError) as e:
        print(f"replay: {e}", file=sys.stderr)
        return 1
    produced = {d.name for d in descs if d.produced_here}

    def wanted(name: str) -> bool:  # the values plan() can choose
        return name in produced and (not words or any(fnmatch.fnmatchcase(name, w) for w in words))

    try:
        rec = load(a.file, wanted)
        chosen, skipped = plan(rec, descs, a.signals, node)
    except (RecordingError, Refusal) as e:
        print(f"replay: {e}", file=sys.stderr)
        return 2
    timeline = sorted((t, seq, d.id, data) for d, name in chosen for t, seq, data in rec.signals[name].values)
    if not timeline:  # channels of this node's signals, but not one value in them
        print(f"replay: {a.file} holds no value of the {len(chosen)} signal(s) node '{node}' produces "
              f"({', '.join(name for _, name in chosen[:8])}{' ...' if len(chosen) > 8 else ''}): "
              "nothing to replay", file=sys.stderr)
        return 2
    if not a.quiet:
        print(f"replay: {len(timeline)} values of {len(chosen)} signals from {a.file} "
              f"(recorded on '{rec.node}') into node '{node}'", file=sys.stderr)
        if skipped:
            print(f"replay: skipped {len(skipped)} signals other nodes produce: "
                  f"{', '.join(skipped[:8])}{' ...' if len(skipped) > 8 else ''}", file=sys.stderr)
    if a.check:
        return 0
    stats_file = None
    if a.stats_json:  # opened before writing anything: no replay ends in a traceback over it
        try:
            stats_file = open(a.stats_json, "w")
        except OSError as e:
            print(f"replay: cannot write {a.stats_json}: {e.strerror}", file=sys.stderr)
            return 1
    stop: List[int] = []
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, lambda *_: stop.append(1))
    # The timeline is hundreds of thousands of objects: a full garbage collection walking
    # them takes milliseconds, in the middle of the timing. Replaying makes no cycles, so
    # what exists is set aside and collection stays off until the end.
    gc.collect()
    gc.freeze()
    gc.disable()
    # As a real-time task does (with --priority): no page of the interpreter, the timeline
    # or what the loop allocates is faulted in or out while it times.
    locked = False
    if a.priority > 0:
        rt = realtime_setup(lock_memory=True, priority=a.priority)
        locked = rt.lock_memory == 0
        if rt.priority:
            print(f"replay: cannot use SCHED_FIFO priority {a.priority} ({os.strerror(-rt.priority)})",
                  file=sys.stderr)
    before = _usage()
    try:
        written, late, why_late = replay(c, timeline, a.rate, a.loop, stop, a.quiet)
    except CcommError as e:
        print(f"\nreplay: {e}", file=sys.stderr)
        return 1
    finally:
        gc.enable()
        c.close()
    # What else could make a write late: page faults that read a file (major), the CPU
    # taken by another task (involuntary switches); said so a late replay says why.
    why_late.update(memory_locked=locked, **{k: v - before[k] for k, v in _usage().items()})
    late.sort()
    stats = {"values": written, "signals": len(chosen), "late_p50_ns": _percentile(late, 0.5),
             "late_p99_ns": _percentile(late, 0.99), "late_max_ns": late[-1] if late else 0, **why_late}
    if not a.quiet:
        print(("\r" if sys.stderr.isatty() else "") + f"replay: wrote {written} values; timing error p50 {stats['late_p50_ns'] / 1e3:.0f} us, "
              f"p99 {stats['late_p99_ns'] / 1e3:.0f} us, max {stats['late_max_ns'] / 1e3:.0f} us; waited for "
              f"ccommd to take a step {why_late['waits_over_1ms']} times 1 ms or more ({why_late['waited_ms']} ms "
              f"in all), {why_late['full_retries']} retries on a full event ring; {why_late['major_faults']} major and "
              f"{why_late['minor_faults']} minor page faults, preempted {why_late['preempted']} times"
              f"{'' if locked else ' (memory not locked)'}", file=sys.stderr)
    if stats_file is not None:
        with stats_file:
            json.dump(stats, stats_file, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
