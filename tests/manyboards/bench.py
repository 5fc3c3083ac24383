#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Many-board benchmark: one-way p50 and per-board ccommd CPU for 2, 4, 8 and 16 boards,
against the bare-socket floor in the same topology, measured in one run.

  tests/manyboards/bench.py --build DIR [--rates 1000,500] [--seconds 5] [--boards 2,4,8,16]
                            [--transports raw,udp] [--out FILE.md] [--json FILE]

Every board writes 4 signals per cycle and consumes the 4 of the previous board in the
ring (the same work per board whatever N is: a board should pay for what it consumes).
Writes the Markdown section (default: print it). Needs root. Used by scripts/bench.
"""

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import manyboards  # noqa: E402
import topology  # noqa: E402


def run_one(args, mode, n, transport, rate):
    a = argparse.Namespace(build=args.build, boards=n, rate=rate, seconds=args.seconds, transport=transport,
                           fanout=args.fanout, monitor="none", consumers=1, signals=4, stale_after_ms=50,
                           stale_tolerance_ms=10, kill=False, prio=70, daemon_prio=80, work=None, latency=True,
                           pin=args.pin)
    r, summary = manyboards.floor(a) if mode == "floor" else manyboards.system(a)
    summary["ok"] = bool(r.checks) and all(ok for ok, _ in r.checks)
    summary["failed"] = [t for ok, t in r.checks if not ok]
    subprocess.run(["rm", "-rf", r.work])
    return summary


def git_commit():
    cp = subprocess.run(["git", "rev-parse", "--short", "HEAD"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                        text=True, cwd=os.path.dirname(os.path.abspath(__file__)))
    return cp.stdout.strip()


def machine():
    model = ""
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    return "%d CPUs (%s), %s, Linux %s, load average %s at the start" % (
        os.cpu_count(), model, platform.machine(), platform.release(), load)


def ratio(x, base):
    return "%.2fx" % (x / base) if x is not None and base else "-"


def render(rows, args, meta):
    us = lambda ns: "%.0f" % (ns / 1e3) if ns is not None else "-"  # noqa: E731
    pct = lambda p: "%.2f" % p if p is not None else "-"  # noqa: E731
    L = ["<!-- SPDX-License-Identifier: Apache-2.0 -->",
         "<!-- Written by tests/manyboards/bench.py (scripts/bench runs it); scripts/bench copies this file "
         "into docs/performance.md. -->",
         "## 9. Many boards on one segment", "",
         "Measured by `tests/manyboards/bench.py` (run by `scripts/bench`) on %s at commit %s. Machine: %s. "
         "N network namespaces, one per board, each joined by a veth pair to one Linux bridge (IGMP snooping "
         "on, the bridge its own querier); in each, one ccommd (SCHED_FIFO 80) and one application "
         "(`bench/manyboards_app.c`, SCHED_FIFO 70) that writes 4 doubles per cycle (%s Hz) and one "
         "`ccomm_flush()` per cycle, and consumes the 4 signals of the previous board in the ring: **the same work "
         "per board for every N**. Cycles of the N boards are spread evenly over the period. Fan-out: %s. %s "
         "p50 is the median over boards of each board's median one-way latency (producer's source time to "
         "the consumer application's read, one CLOCK_MONOTONIC for all namespaces); CPU is ccommd's "
         "run time over the run (every thread's `/proc/PID/task/TID/schedstat`, ns) as %% of one core, the median over boards. "
         "The floor is `bench/manyboards_floor.c` in the same topology: one bare socket per board "
         "sending one frame per cycle to its own multicast group and receiving the groups it wants (raw: "
         "through a kernel socket filter, as ccommd). CPU pressure is the share of the ccomm run during which "
         "some task on the host waited for a CPU (`/proc/pressure/cpu`): the VM is shared with other builds, "
         "so single 5 s runs vary (three runs on 2026-11-25 differed by up to about 30 %% per ccomm cell, the floor's "
         "small CPU figures by more)."
         % (meta["date"], meta["commit"], meta["machine"], " and ".join("%g" % x for x in args.rates), args.fanout,
            "Placement: each board's processes (ccommd's threads and the application) on one CPU, board i on CPU "
            "i mod %d, as a single-core board (an Overo) runs them; the floor's likewise (`--no-pin`: the host "
            "spreads them over all CPUs; measured that way on 2026-12-04, each application migrated between the CPUs "
            "1300-1400 times a second (/proc/PID/task/TID/sched) and ccommd's per-board CPU at 1 kHz was 5.4-7.6 %% "
            "instead of 2.7-4.1 %%, p50 at 2 boards 101-134 us instead of 54-60 us)." % os.cpu_count() if getattr(args, "pin", True) else
            "Placement: unpinned (`--no-pin`): the host spreads each board's processes over all CPUs."),
         ""]
    for tr, rate in [(t, x) for x in args.rates for t in args.transports]:
        R = [r for r in rows if r["transport"] == tr and r["rate"] == rate]
        base = next((r for r in R if r["boards"] == min(args.boards)), None)
        L += ["| %s %g Hz, boards | ccomm p50 us | vs %d boards | ccommd CPU %% | vs %d boards | ccommd wake-ups / cycle | "
              "app CPU %% | floor p50 us | floor CPU %% | CPU pressure %% | all values exact |"
              % (tr, rate, min(args.boards), min(args.boards)),
              "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---|"]
        for r in R:
            c, f = r["ccomm"], r["floor"]
            wakes = c.get("wakeups_per_cycle_per_board")
            L.append("| %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                r["boards"], us(c.get("p50_ns")), ratio(c.get("p50_ns"), base["ccomm"].get("p50_ns")),
                pct(c.get("cpu_pct_per_board")),
                ratio(c.get("cpu_pct_per_board"), base["ccomm"].get("cpu_pct_per_board")),
                "%.2f" % wakes if wakes is not None else "-",
                pct(c.get("app_cpu_pct_per_board")), us(f.get("p50_ns")), pct(f.get("cpu_pct_per_board")),
                "%.0f" % (100 * c["cpu_pressure"]) if c.get("cpu_pressure") is not None else "-",
                "yes" if c.get("ok") else "**no**: " + "; ".join(c.get("failed", []))[:200]))
        L.append("")
    checks = []
    for tr, rate in [(t, x) for x in args.rates for t in args.transports]:
        R = [r for r in rows if r["transport"] == tr and r["rate"] == rate]
        base = next((r for r in R if r["boards"] == min(args.boards)), None)
        for r in R:
            if r is base:
                continue
            for key, what in (("p50_ns", "p50"), ("cpu_pct_per_board", "per-board CPU")):
                b, x = base["ccomm"].get(key), r["ccomm"].get(key)
                if b and x is not None:
                    checks.append((x <= 1.10 * b, "%s %g Hz, %d boards: %s %s the %d-board figure"
                                   % (tr, rate, r["boards"], what, ratio(x, b), min(args.boards))))
    missed = [t for ok, t in checks if not ok]
    L.append("Target (issue 14): per-board CPU and p50 within 10 %% of the %d-board figure (lower is fine): met in "
             "%d of %d comparisons%s." % (min(args.boards), len(checks) - len(missed), len(checks),
                                          "; missed: " + "; ".join(missed) if missed else ""))
    L += ["", "How the design gets there: with `fanout=\"multicast\"` a producing board sends each cycle's values "
          "once, to its own group (raw: MAC 03:63:63:6d:00:ID; UDP: 239.255.67.ID), whatever the number of "
          "consumers, so its send cost does not grow with N (the test counts exactly one data frame per cycle "
          "per board on the bridge). A board joins only the groups of the boards it consumes from (a board that only consumes from it sends it heartbeats directly, ten a second: the test checks that it gets no data frames from such a board). "
          "With UDP the bridge's IGMP snooping delivers it only those streams, so its receive cost follows what "
          "it consumes, not the size of the system. Raw Ethernet multicast is flooded by a plain bridge or "
          "unmanaged switch to every port; ccommd's packet socket carries a kernel socket filter for the "
          "joined groups, so the frames of other groups are dropped in the kernel without waking ccommd (the "
          "floor does the same). What does grow with N is the host: all boards share these 2 CPUs, so at 1 kHz x 16 boards "
          "(ccommd + application about 9 % of a core per board, 16 x 1000 cycles/s with ~8 thread wake-ups "
          "each) the machine is close to saturation and the applications' SCHED_FIFO threads start waking "
          "late; on real boards each has its own CPU. And the host charges the network's work to the wrong board: "
          "this kernel has no IRQ time accounting (CONFIG_IRQ_TIME_ACCOUNTING off), so the softirq work of every "
          "frame (veth, bridge, IP and UDP receive, for any board) is counted to whichever thread runs when it "
          "does, and how much of the other boards' lands on a board's ccommd depends on how the N boards' cycles "
          "fall on the 2 CPUs, not on what the board does; per-board CPU can therefore move with N where the board's own work does not. What a "
          "board's ccommd itself does per cycle is the wake-up column (its threads' voluntary context switches "
          "over the run / cycles, median over boards: the send thread once per flush, the receive thread once "
          "per frame it consumes, the supervision tick about 10 a second) and the frame checks above (its data "
          "frames, and none of the data of boards that only consume from it): both constant in N.", ""]
    return "\n".join(L) + "\n", checks


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--rates", default="1000,500", help="cycles per second, each measured (default 1000,500)")
    ap.add_argument("--seconds", type=float, default=5)
    ap.add_argument("--boards", default="2,4,8,16")
    ap.add_argument("--transports", default="raw,udp")
    ap.add_argument("--fanout", choices=("multicast", "unicast"), default="multicast")
    ap.add_argument("--no-pin", dest="pin", action="store_false",
                    help="let the host spread each board's processes over all CPUs (default: board i on CPU i mod CPUs)")
    ap.add_argument("--out", help="write the Markdown section here (default: stdout)")
    ap.add_argument("--json", help="also write the measurements here")
    ap.add_argument("--from-json", help="measure nothing: render the section again from this --json file")
    args = ap.parse_args()
    args.boards = [int(x) for x in args.boards.split(",")]
    args.transports = args.transports.split(",")
    args.rates = [float(x) for x in args.rates.split(",")]
    if os.geteuid() != 0:
        print("manyboards bench: needs root", file=sys.stderr)
        return 4
    if args.from_json:
        with open(args.from_json) as f:
            data = json.load(f)
        text, _ = render(data["rows"], args, data["meta"])
        if args.out:
            with open(args.out, "w") as f:
                f.write(text)
        else:
            sys.stdout.write(text)
        return 0
    topology.sweep_stale()
    meta = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "commit": git_commit(), "machine": machine()}
    rows = []
    for tr, rate in [(t, x) for x in args.rates for t in args.transports]:
        for n in args.boards:
            row = {"boards": n, "transport": tr, "rate": rate}
            row["floor"] = run_one(args, "floor", n, tr, rate)
            row["ccomm"] = run_one(args, "run", n, tr, rate)
            print("manyboards bench: %s %g Hz %2d boards: ccomm p50 %s us cpu %.2f%%, floor p50 %s us cpu %.2f%%%s" % (
                tr, rate, n, row["ccomm"].get("p50_ns", 0) / 1e3, row["ccomm"].get("cpu_pct_per_board", -1),
                row["floor"].get("p50_ns", 0) / 1e3, row["floor"].get("cpu_pct_per_board", -1),
                "" if row["ccomm"]["ok"] else " (checks failed)"), file=sys.stderr, flush=True)
            rows.append(row)
    text, checks = render(rows, args, meta)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"meta": meta, "rows": rows}, f, indent=1)
    if args.out:
        with open(args.out + ".tmp", "w") as f:
            f.write(text)
        os.replace(args.out + ".tmp", args.out)
    else:
        sys.stdout.write(text)
    for ok, t in checks:
        print("target %-6s %s" % ("met" if ok else "missed", t), file=sys.stderr)
    # Checks that failed are in the table (a saturated host is a result, not an error).
    return 0 if rows else 1


if __name__ == "__main__":
    sys.exit(main())
