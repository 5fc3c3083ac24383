# SPDX-License-Identifier: Apache-2.0
"""Where the CPU of one value goes, thread by thread (issue 38): while a one-way case
runs, every thread of its programs (ccommd and ccomm-latency, or dds_pingpong) is read
twice from /proc, once the traffic is steady and a window later: run time from
schedstat (ns, exact), user and system from stat (100 Hz ticks: coarse), voluntary
context switches (wake-ups after sleeping) and involuntary ones. The board a process
belongs to is its CPU (board A = CPU 0, board B = CPU 1: the bench pins them). Per value =
per value the sender wrote in the window (1 kHz: one per ms).

  Sampler(programs, lead_s, window_s).start() ... .stop() -> a sample dict (or None)
  table(rows) -> Markdown lines: each row's threads per value, summed over its rounds
"""

import os
import threading
import time

PROGRAMS = ("ccommd", "ccomm-latency", "dds_pingpong")


def _read(path):
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return None


def snapshot(programs=PROGRAMS):
    """{(pid, tid): record} for every thread of the running processes named `programs`."""
    out = {}
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        comm = (_read("/proc/%s/comm" % pid) or "").strip()
        if comm not in programs:
            continue
        status = _read("/proc/%s/status" % pid) or ""
        cpus = next((l.split(":", 1)[1].strip() for l in status.splitlines() if l.startswith("Cpus_allowed_list")), "")
        board = {"0": "A", "1": "B"}.get(cpus, "cpus " + cpus)
        try:
            tids = os.listdir("/proc/%s/task" % pid)
        except OSError:
            continue
        for tid in tids:
            base = "/proc/%s/task/%s/" % (pid, tid)
            st, ss, ts = _read(base + "stat"), _read(base + "schedstat"), _read(base + "status")
            name = (_read(base + "comm") or "").strip()
            if not st or not ss or not ts:
                continue
            f = st[st.rfind(")") + 2:].split()
            sw = {l.split(":")[0]: int(l.split()[1]) for l in ts.splitlines() if l.endswith(tuple("0123456789"))
                  and l.split(":")[0] in ("voluntary_ctxt_switches", "nonvoluntary_ctxt_switches")}
            out[(pid, tid)] = {"board": board, "process": comm, "thread": name, "utime": int(f[11]),
                               "stime": int(f[12]), "run_ns": int(ss.split()[0]),
                               "vcsw": sw.get("voluntary_ctxt_switches", 0),
                               "ivcsw": sw.get("nonvoluntary_ctxt_switches", 0)}
    return out


class Sampler:
    """Waits (in a thread of its own) until `need` processes of `programs` run, then `lead_s`
    more, reads every thread, waits `window_s`, reads again. stop() joins it and returns the
    differences of the threads seen both times, or None if the window never completed."""

    def __init__(self, programs=PROGRAMS, need=2, lead_s=0.6, window_s=1.0, rate_hz=1000):
        self.programs, self.need, self.lead_s, self.window_s, self.rate_hz = programs, need, lead_s, window_s, rate_hz
        self.result, self._stop = None, threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self._thread.start()
        return self

    def _run(self):
        deadline = time.monotonic() + 30
        while not self._stop.is_set() and time.monotonic() < deadline:
            apps = {k[0] for k, v in snapshot(self.programs).items() if v["process"] != "ccommd"}
            if len(apps) >= self.need:
                break
            time.sleep(0.02)
        else:
            return
        if self._stop.wait(self.lead_s):
            return
        a, t0 = snapshot(self.programs), time.monotonic()
        if self._stop.wait(self.window_s):
            return
        b, wall = snapshot(self.programs), time.monotonic() - t0
        threads = []
        for k, y in b.items():
            x = a.get(k)
            if x is None:
                continue
            threads.append(dict(board=y["board"], process=y["process"], thread=y["thread"],
                                **{f: y[f] - x[f] for f in ("utime", "stime", "run_ns", "vcsw", "ivcsw")}))
        self.result = {"window_s": round(wall, 4), "values": round(wall * self.rate_hz), "threads": threads}

    def stop(self):
        self._stop.set()
        self._thread.join(5)
        return self.result


def table(rows):
    """Markdown: for each row (its samples of every round summed), per value: run time (µs),
    user and system ticks' share of it, wake-ups (voluntary switches) and preemptions, by
    board, process and thread; a total line per row."""
    L = []
    for r in rows:
        samples = [s for s in (r.get("threads") or []) if s]
        if not samples:
            continue
        values = sum(s["values"] for s in samples)
        groups = {}
        for s in samples:
            for t in s["threads"]:
                # DDS names its threads (recvUC, tev, dq.builtins, ...); a process's other
                # unnamed threads carry its own name.
                g = groups.setdefault((t["board"], t["process"], t["thread"]), dict(n=0, run_ns=0, utime=0, stime=0,
                                                                                  vcsw=0, ivcsw=0))
                g["n"] += 1
                for f in ("run_ns", "utime", "stime", "vcsw", "ivcsw"):
                    g[f] += t[f]
        L.append("`%s` (%d values in %d window%s of %.1f s):\n" % (r["name"], values, len(samples),
                                                                  "" if len(samples) == 1 else "s",
                                                                  samples[0]["window_s"]))
        L.append("| board | process | thread | µs run / value | user : system (ticks) | wake-ups / value | "
                 "preempted / value |")
        L.append("|:---|:---|:---|---:|---:|---:|---:|")
        tot = dict(run_ns=0, vcsw=0, ivcsw=0, utime=0, stime=0)
        for (board, proc, thread), g in sorted(groups.items()):
            if g["run_ns"] == 0 and g["vcsw"] == 0:
                continue  # a thread that slept through the window
            for f in tot:
                tot[f] += g[f]
            L.append("| %s | %s | %s | %.2f | %d : %d | %.3f | %.3f |" % (
                board, proc, thread, g["run_ns"] / 1e3 / values, g["utime"], g["stime"], g["vcsw"] / float(values),
                g["ivcsw"] / float(values)))
        L.append("| | **all** | | **%.2f** | %d : %d | **%.3f** | %.3f |" % (
            tot["run_ns"] / 1e3 / values, tot["utime"], tot["stime"], tot["vcsw"] / float(values),
            tot["ivcsw"] / float(values)))
        L.append("")
    return L
