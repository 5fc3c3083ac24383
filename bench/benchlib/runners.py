# SPDX-License-Identifier: Apache-2.0
"""How scripts/bench measures each kind of ccomm case of the plan (suite.CCase.kind):
on-target (ccomm_local, ccomm_pp), board -> board (ccomm_pair), the thesis experiments
(thesis), cost (idle, callgrind, callgrind_client) and large values (large.py). Each
runner takes the suite.Bench context and the case and returns its rows (cost runners
leave their data in ctx.cost); RUNNERS maps a kind to its runner."""

import dataclasses
import os
import resource
import shutil
import time

from . import callgrind, ccomm, large, peers, procs
from .ccomm import Daemons, Failed, Skip

# A spinning SCHED_FIFO thread is throttled after 0.95 s of every second
# (sched_rt_runtime_us): a spinning receiver's whole life (lead, warm-up, samples and
# ccomm-latency's 0.2 s tail) stays below that.
SPIN_SECONDS = 0.4
SPIN_WARMUP = 0.15
SPIN_LEAD = 0.05


# ---- on-target ----

def run_local(ctx, case):
    ctx.need("ccommd", "ccomm", "ccomm-latency")
    o = case.opts
    if o["event"]:
        sigs = [ccomm.LOCAL_EVENT]
    else:
        sigs = ccomm.LOCAL_STATES[:o["signals"]]
    a, b = ctx.cpu("a"), ctx.cpu("b")
    cfg = ccomm.local_config(ctx.daemon_prio, a)
    with Daemons(ctx.bins, cfg, [(ccomm.LOCAL_NODE, None, a)], ctx.workdir, case.name, no_rt=ctx.no_rt) as d:
        samples = os.path.join(ctx.workdir, case.name + ".samples")
        # One process, two threads on two CPUs: the sending (main) thread writes and
        # flushes each cycle on CPU a, the receive thread waits (or spins) on CPU b.
        spin = o["style"] == "spin"
        warm = SPIN_WARMUP if spin else 0.5
        argv = ccomm.latency_argv(ctx.bins, ccomm.LOCAL_NODE, o["rate"], case.seconds + warm, ctx.prio, case.name,
                                  samples, send=sigs, recv=sigs, spin=spin, rx_cpu=b, warmup=warm,
                                  rx_prio=_rx_prio(ctx) if spin else None)
        argv = ccomm.placed(argv, ctx.prio, [a] if a is not None else None)
        res = ccomm.run_apps(d, [("app", argv, 0.0)], case.seconds + 30)["app"]
    row = ccomm.samples_row(case.name, "shm", 8 * len(sigs), o["rate"], res, samples, ctx.rawdir,
                            style=o["style"], signal_kind="event" if o["event"] else "state",
                            signals=len(sigs), command=argv)
    return [row]


def run_pingpong(ctx, case):
    """ccomm_pingpong: echo and ping processes on CPUs b and a through one node's
    segment (its ccommd running), back to back, RTT/2 like shm_floor and iox_pingpong."""
    ctx.need("ccommd", "ccomm_pingpong")
    o = case.opts
    ping, pong = ccomm.PINGPONG[(o["kind"], o["payload"])]
    a = ctx.cpu("a")
    with Daemons(ctx.bins, ccomm.local_config(ctx.daemon_prio, a), [(ccomm.LOCAL_NODE, None, a)], ctx.workdir,
                 case.name, no_rt=ctx.no_rt) as d:
        exe = ["env", "CCOMM_SHM_PREFIX=" + d.prefix, ctx.bins["ccomm_pingpong"], "--node", ccomm.LOCAL_NODE,
               "--ping", ping, "--pong", pong, "--wait", o["wait"], "--payload", str(o["payload"])]
        if o["clock"] == "cycle":
            exe.append("--cycle-time")
        floor_shm = None
        if o.get("interleave"):
            floor_shm = "/ccbench-floor-%d-%s" % (os.getpid(), case.name)
            exe += ["--floor-shm", floor_shm, "--block", "1000"]
        cpu0 = _cpu_mark(d, [ccomm.LOCAL_NODE])
        argv = exe + ["--role", "ping", "--half", "--name", case.name, "--count", str(o["count"]),
                      "--warmup", "1000", "--dump", os.path.join(ctx.rawdir, case.name + ".tsv")] + ctx.side_opts("a")
        try:
            row = procs.ping_with_echo(exe + ["--role", "echo"] + ctx.side_opts("b"),
                                       os.path.join(ctx.workdir, case.name + ".echo.log"),
                                       argv, 60, os.path.join(ctx.workdir, case.name + ".ping.log"))
        finally:
            if floor_shm and os.path.exists("/dev/shm" + floor_shm):
                os.unlink("/dev/shm" + floor_shm)  # the ping removes it; not after a failure
        cpu_ns = _cpu_since(d, [ccomm.LOCAL_NODE], cpu0)
    # CPU per value (issue 30): both processes' whole lives and ccommd, per value handed over
    # (two per round trip; interleaved floor blocks count too: they ran in the same processes).
    trips = row["count"] + row["lost"] + 1000 + (row.get("floor_count") or 0)
    if cpu_ns is not None:
        row.update(cpu_ns, values=2 * trips, cpu_ns_per_value=round(cpu_ns["cpu_ns"] / (2.0 * trips)))
    row["raw"] = os.path.relpath(os.path.join(ctx.rawdir, case.name + ".tsv"), ctx.outdir)
    row.update(style=o["wait"], signal_kind=o["kind"], clock=o["clock"], command=argv)
    return [row]


# ---- board -> board ----

def _names(exp):
    return ("control", "planner") if exp == "setup" else ("client", "server")


def _pair(ctx, case, a2b, b2a, transport, periodic_hz=0, names=("client", "server"), wrapper=(), no_rt=None,
          ready_timeout=10.0):
    ns = ctx.netns()
    cfg = ccomm.pair_config(names, a2b, b2a, transport, ns, periodic_hz, ctx.daemon_prio,
                            ctx.cpus if ctx.cpus else None)
    nodes = [(names[0], "a", ctx.cpu("a")), (names[1], "b", ctx.cpu("b"))]
    return Daemons(ctx.bins, cfg, nodes, ctx.workdir, case.name, ns_pair=ns, wrapper=wrapper,
                   no_rt=ctx.no_rt if no_rt is None else no_rt, ready_timeout=ready_timeout)


def _rx_prio(ctx):
    """A spinning receive thread runs below the sending thread (and far below ccommd),
    so it never starves either on its CPU."""
    return max(1, ctx.prio - 10) if ctx.prio else None


def _app(ctx, d, side, node, rate, duration, label, samples, mode="oneway", spin=False, warmup=0.5):
    cpu = ctx.cpu(side)
    argv = ccomm.latency_argv(ctx.bins, node, rate, duration, ctx.prio, label, samples, mode=mode, spin=spin,
                              warmup=warmup, rx_prio=_rx_prio(ctx) if spin else None, stages=True)
    return d.wrap(side, ccomm.placed(argv, ctx.prio, [cpu] if cpu is not None else None))


def _snapshot(d, names):
    out = d.stats_all(list(names))
    for n, st in out.items():
        if st is None:
            raise Failed("ccomm stats --json failed for %s" % n)
    return out


class LinkProbe:
    """Packets each namespace's eth0 sent between two instants while the apps run:
    frames per cycle in steady state (periodic frames go on after the apps stop, so
    whole-run counters cannot tell). pids: a process in namespace a and one in b."""

    def __init__(self, pids):
        self.pids = pids
        self.marks = []

    def mark(self):
        # Timestamp and counters belong together: retry if this (SCHED_OTHER) script was
        # descheduled while reading them.
        for _ in range(10):
            t0 = time.monotonic()
            a, b = ccomm.link_stats(self.pids[0]), ccomm.link_stats(self.pids[1])
            t1 = time.monotonic()
            if t1 - t0 < 0.001:
                break
        self.marks.append(((t0 + t1) / 2, a, b))

    def per_cycle(self, side, rate):
        if len(self.marks) < 2:
            return None
        (t0, a0, b0), (t1, a1, b1) = self.marks[0], self.marks[-1]
        x0, x1 = (a0, a1) if side == "a" else (b0, b1)
        if not x0 or not x1 or t1 <= t0:
            return None
        return round((x1[0] - x0[0]) / ((t1 - t0) * rate), 3)


def run_pair(ctx, case):
    ctx.need("ccommd", "ccomm", "ccomm-latency")
    o = case.opts
    k = o["signals"]
    count = o.get("count", 1)  # > 1: each signal an array of that many doubles
    names = ("client", "server")
    arr = ":%d" % count if count > 1 else ""
    a2b = ["x%d%s" % (i, arr) for i in range(k)]
    b2a = ["y%d%s" % (i, arr) for i in range(k)] if o["mode"] == "ping" else []
    spin = o["style"] == "spin"
    warm = SPIN_WARMUP if spin else 0.5
    rate, dur = o["rate"], case.seconds + warm
    with _pair(ctx, case, a2b, b2a, o["transport"], names=names) as d:
        sa = os.path.join(ctx.workdir, case.name + ".a.samples")
        sb = os.path.join(ctx.workdir, case.name + ".b.samples")
        before = _snapshot(d, names)
        cpu0 = _cpu_mark(d, names)
        if o["mode"] == "ping":
            apps = [("b", _app(ctx, d, "b", names[1], rate, dur + 0.6, case.name + "-echo", sb, mode="echo"), 0.0),
                    ("a", _app(ctx, d, "a", names[0], rate, dur, case.name, sa, mode="ping"), 0.3)]
        else:
            # The receiver starts first and ends last (a spinning one only just).
            lead = SPIN_LEAD if spin else 0.3
            apps = [("b", _app(ctx, d, "b", names[1], rate, dur + 2 * lead, case.name, sb, spin=spin, warmup=warm),
                     0.0),
                    ("a", _app(ctx, d, "a", names[0], rate, dur, case.name + "-src", sa, warmup=warm), lead)]
        with ccomm.DaemonCpuSampler(d, names) as sampler:
            res = ccomm.run_apps(d, apps, dur + 30)
        cpu_ns = _cpu_since(d, names, cpu0)
        after = _snapshot(d, names)
    dirn = ccomm.delta_stats(before, after, names[0], names[1])
    extra = dict(style=o["style"], signals=k, elements=count, signal_kind="state", wire=dirn, sent=res["a"]["sent"],
                 frames_per_cycle=_ratio(dirn["data_frames"], res["a"]["sent"]),
                 command=res["b"]["argv"] if o["mode"] == "oneway" else res["a"]["argv"],
                 daemon_command=d.argv[names[0]])
    # CPU per value, per value delivered (a round trip delivers two), counted as the peers'
    # rows count theirs: each application over its measured window (its send loop, or from
    # its first value received to its end: ccomm-latency's window_*), both ccommds over the
    # span of the two windows (sampled, interpolated). The whole lives (start-up, attach,
    # memory locking, the leads between the applications) are kept beside it (_whole).
    values = (res["a"].get("sent") or 0) * (2 if o["mode"] == "ping" else 1)
    if cpu_ns is not None and values:
        extra.update({k + "_whole": v for k, v in cpu_ns.items()})
        extra.update(values=values, cpu_ns_whole_per_value=round(cpu_ns["cpu_ns"] / float(values)))
        window = _window_cpu(res, sampler)
        if window is not None:
            extra.update(window, cpu_ns_per_value=round(window["cpu_ns"] / float(values)))
        else:  # no windows reported: the whole lives, said so in the row
            extra.update(cpu_ns, cpu_basis="whole lives", cpu_ns_per_value=extra["cpu_ns_whole_per_value"])
    if o["mode"] == "ping":
        row = ccomm.samples_row(case.name, o["transport"], 8 * k * count, rate, res["a"], sa, ctx.rawdir,
                                metric="rtt_half", **extra)
    else:
        row = ccomm.samples_row(case.name, o["transport"], 8 * k * count, rate, res["b"], sb, ctx.rawdir,
                                **extra)
    return [row]


def _window_cpu(res, sampler):
    """{"cpu_ns", "cpu_apps_ns", "cpu_daemons_ns", "window_ns"} over the applications'
    measured windows (see run_pair), or None when an application reported none."""
    sides = [res[s] for s in ("a", "b") if s in res]
    if any(not r.get("window_end_ns") for r in sides):
        return None
    start = min(r["window_start_ns"] for r in sides)
    end = max(r["window_end_ns"] for r in sides)
    daemons = sampler.between(start, end)
    if daemons is None:
        return None
    apps = sum(int(r["window_cpu_ns"]) for r in sides)
    return {"cpu_ns": apps + daemons, "cpu_apps_ns": apps, "cpu_daemons_ns": daemons, "window_ns": end - start,
            "cpu_daemon_threads": {role: {"run_ns": run, "times_run": times}
                                   for role, (run, times) in sampler.threads_between(start, end).items()}}


def _cpu_mark(d, names):
    """CPU time so far of the waited-for children (the applications, once they exit) and
    of each ccommd's threads (schedstat ns)."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    daemons = {n: (d.cpu(n) or (0, 0))[1] for n in names}
    return (ru.ru_utime + ru.ru_stime) * 1e9, daemons


def _cpu_since(d, names, mark):
    """{"cpu_ns", "cpu_apps_ns", "cpu_daemons_ns"} used since _cpu_mark() by the
    applications run in between (utime+stime of every waited-for child) and by the
    ccommds; None if a daemon could not be read."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    apps = int((ru.ru_utime + ru.ru_stime) * 1e9 - mark[0])
    daemons = 0
    for n in names:
        c = d.cpu(n)
        if c is None:
            return None
        daemons += c[1] - mark[1][n]
    return {"cpu_ns": apps + daemons, "cpu_apps_ns": apps, "cpu_daemons_ns": daemons}


def run_throughput(ctx, case):
    """8 B one way (one state signal, sent as the application flushes) at the peers'
    rising rates (peers.sweep) until the receiving application misses values."""
    def measure(rate):
        sub = dataclasses.replace(case, name="%s_%d" % (case.name, rate),
                                  seconds=max(case.seconds, case.opts["min_values"] / float(rate)),
                                  opts={"transport": case.opts["transport"], "signals": 1, "mode": "oneway",
                                        "style": "block", "rate": rate})
        return run_pair(ctx, sub)[0]
    row = peers.sweep(measure, [r for r in peers.THROUGHPUT_RATES if r])
    row["name"] = case.name
    return [row]


def _ratio(a, b):
    return round(a / b, 3) if b else None


def _wakeups(before, after, node):
    """ccommd's send-thread wake-ups between two snapshots (counters.tx_wakeups)."""
    return after[node]["counters"].get("tx_wakeups", 0) - before[node]["counters"].get("tx_wakeups", 0)


# ---- the thesis experiments ----

def run_thesis(ctx, case):
    ctx.need("ccommd", "ccomm", "ccomm-latency")
    o = case.opts
    exp, mode, rate = o["exp"], o["mode"], o["rate"]
    spin = o.get("style") == "spin"
    warm = SPIN_WARMUP if spin else 0.5
    names = _names(exp)
    if exp == "setup":
        a2b, b2a = ccomm.SETUP_A2B, ccomm.SETUP_B2A
    else:
        a2b, b2a = ["value"], []
    dur = case.seconds + warm
    periodic = rate if mode == "periodic" else 0
    with _pair(ctx, case, a2b, b2a, "raw", periodic, names) as d:
        sa = os.path.join(ctx.workdir, case.name + ".a.samples")
        sb = os.path.join(ctx.workdir, case.name + ".b.samples")
        before = _snapshot(d, names)
        pids = (d.pid(names[0]), d.pid(names[1]))  # ccommd of board A, of board B
        link0 = ccomm.link_stats(pids[0]), ccomm.link_stats(pids[1])
        meter = ccomm.CpuMeter(d)
        meter.start()
        lead = SPIN_LEAD if spin else 0.3
        if exp == "setup":
            # Both boards send and receive at once, as in the thesis' use case.
            apps = [("a", _app(ctx, d, "a", names[0], rate, dur, case.name + "_a2b", sa, spin=spin, warmup=warm),
                     0.0),
                    ("b", _app(ctx, d, "b", names[1], rate, dur, case.name + "_b2a", sb, spin=spin, warmup=warm),
                     0.0)]
        else:
            apps = [("b", _app(ctx, d, "b", names[1], rate, dur + 2 * lead, case.name, sb, spin=spin, warmup=warm),
                     0.0),
                    ("a", _app(ctx, d, "a", names[0], rate, dur, case.name + "-src", sa, warmup=warm), lead)]
        probe = LinkProbe(pids)
        # Two marks inside the steady part of the run (after the warm-up, before the end);
        # not with spinning receivers, which starve this (SCHED_OTHER) script on both CPUs.
        first = lead if exp == "single" else 0.0
        probes = [] if spin else [(first + warm + 0.05, probe.mark), (first + dur - 0.1, probe.mark)]
        res = ccomm.run_apps(d, apps, dur + 30, probes)
        cpu = meter.stop()
        after = _snapshot(d, names)
        link1 = ccomm.link_stats(pids[0]), ccomm.link_stats(pids[1])
    sig = {n: ccomm.signal_totals(before, after, n) for n in names}
    forwarded = sig[names[0]]["rx"] + sig[names[1]]["rx"]  # values stored on the far side
    common = dict(exp=exp, mode=mode, cpu=cpu, forwarded=forwarded, signal_totals=sig,
                  daemon_command=d.argv[names[0]])
    rows = []
    dirs = [("a2b", names[0], names[1], "a", "b", len(a2b))]
    if b2a:
        dirs.append(("b2a", names[1], names[0], "b", "a", len(b2a)))
    for tag, src, dst, src_side, dst_side, k in dirs:
        w = ccomm.delta_stats(before, after, src, dst)
        li = 0 if src_side == "a" else 1
        pk = by = None
        if link0[li] and link1[li]:
            pk, by = link1[li][0] - link0[li][0], link1[li][1] - link0[li][1]
        recv_res = res[dst_side]
        sent = res[src_side]["sent"]
        samples = sa if dst_side == "a" else sb
        name = case.name + ("_" + tag if exp == "setup" else "")
        row = ccomm.samples_row(name, "raw", 8 * k, rate, recv_res, samples, ctx.rawdir,
                                style="spin" if spin else "block",
                                signals=k, signal_kind="state", direction=tag, wire=w, sent=sent,
                                # Whole-run frame count: exact for event-driven sending; periodic
                                # frames continue after the apps stop, so there only the
                                # steady-state packet rate says anything.
                                frames_per_cycle=_ratio(w["data_frames"], sent) if mode == "event" else None,
                                packets_per_cycle=probe.per_cycle(src_side, rate),
                                tx_wakeups_per_cycle=_ratio(_wakeups(before, after, src), sent),
                                bytes_per_frame=_ratio(by, pk) if pk else None,
                                wire_signals_lost=sig[dst]["lost"], command=res[dst_side]["argv"], **common)
        rows.append(row)
    return rows


# ---- cost ----

def run_idle(ctx, case):
    """Both daemons of the setup-simulation up, no application: CPU per second."""
    ctx.need("ccommd", "ccomm")
    names = _names("setup")
    with _pair(ctx, case, ccomm.SETUP_A2B, ccomm.SETUP_B2A, "raw", 0, names) as d:
        meter = ccomm.CpuMeter(d)
        meter.start()
        time.sleep(case.seconds)
        cpu = meter.stop()
    ctx.cost["idle"] = cpu
    return []


def run_callgrind(ctx, case):
    """Both daemons under callgrind: once with traffic, once idle for as long; the
    difference in instructions over the signals each handled (sent + received) is the
    user-space cost per forwarded signal (syscalls and the kernel are not counted)."""
    ctx.need("ccommd", "ccomm", "ccomm-latency")
    vg = shutil.which("valgrind")
    if not vg:
        raise Skip("valgrind not installed (Debian: valgrind)")
    o = case.opts
    names = _names(o["exp"])
    a2b, b2a = (ccomm.SETUP_A2B, ccomm.SETUP_B2A) if o["exp"] == "setup" else (["value"], [])
    out = {}
    for phase in ("traffic", "idle"):
        tag = "%s.%s" % (case.name, phase)
        files = {n: os.path.join(ctx.workdir, "%s.%s.callgrind" % (tag, n)) for n in names}
        for f in files.values():
            if os.path.exists(f):
                os.unlink(f)

        def wrapper(node, files=files):
            return [vg, "--tool=callgrind", "--callgrind-out-file=" + files[node], "--dump-instr=no"]

        sub = dataclasses.replace(case, name=tag, seconds=0, opts={})
        with _pair(ctx, sub, a2b, b2a, "raw", 0, names, wrapper=wrapper, no_rt=True, ready_timeout=60.0) as d:
            before = _snapshot(d, names)
            t0 = time.monotonic()
            if phase == "traffic":
                apps = [(side, _app(ctx, d, side, node, o["rate"], case.seconds, "%s_%s" % (tag, side),
                                    os.path.join(ctx.workdir, "%s.%s.samples" % (tag, side))), 0.0)
                        for side, node in (("a", names[0]), ("b", names[1]))]
                ccomm.run_apps(d, apps, case.seconds + 60)
            # The same daemon lifetime in both phases: the idle work cancels out.
            left = case.seconds + 0.3 - (time.monotonic() - t0)
            if left > 0:
                time.sleep(left)
            after = _snapshot(d, names)
        per = {}
        for n in names:
            if not os.path.exists(files[n]):
                raise Failed("callgrind wrote no profile for %s" % n)
            sig = ccomm.signal_totals(before, after, n)
            per[n] = {"ir": callgrind.total_ir(files[n]), "tx": sig["tx"], "rx": sig["rx"],
                      "file": os.path.relpath(files[n], ctx.outdir)}
        out[phase] = per
    res = {"exp": o["exp"], "rate": o["rate"], "seconds": case.seconds, "nodes": {}}
    for n in names:
        t, i = out["traffic"][n], out["idle"][n]
        handled = t["tx"] + t["rx"]
        calls = callgrind.inclusive_calls(os.path.join(ctx.outdir, t["file"]))
        res["nodes"][n] = {"ir_traffic": t["ir"], "ir_idle": i["ir"], "tx": t["tx"], "rx": t["rx"],
                           "ir_per_signal": round((t["ir"] - i["ir"]) / handled, 1) if handled else None,
                           "per_call": callgrind.per_call(calls, DAEMON_FUNCTIONS), "file": t["file"]}
    ctx.cost.setdefault("callgrind", {})[o["exp"]] = res
    return []


# What a forwarded signal and a frame cost inside ccommd, by function (inclusive Ir per call).
DAEMON_FUNCTIONS = [
    ("send: collect one signal from shared memory and encode it", "SendPath::CollectSignal("),
    ("send: add one entry to the frame (wire encoding)", "FrameWriter::Add("),
    ("send: finish and send one frame (user part of sendto)", "SendPath::FlushPeer("),
    ("receive: validate one frame and store its entries", "ReceivePath::HandleFrame("),
    ("receive: one transport receive call (user part of recvfrom)", "RawRecv("),
    ("supervision tick", "Supervisor::Tick("),
]

CLIENT_FUNCTIONS = [
    ("ccomm_write_double (one signal)", "ccomm_write_double"),
    ("ccomm_flush (once per cycle: the doorbell)", "ccomm_flush"),
    ("ccomm_read_double (one signal)", "ccomm_read_double"),
    ("ccomm_wait (user part)", "ccomm_wait"),
]


def run_callgrind_client(ctx, case):
    """The application side (libccomm) under callgrind: instructions per write, flush,
    read and wait, on one board (local signals, blocking receive)."""
    ctx.need("ccommd", "ccomm", "ccomm-latency")
    vg = shutil.which("valgrind")
    if not vg:
        raise Skip("valgrind not installed (Debian: valgrind)")
    o = case.opts
    sigs = ccomm.LOCAL_STATES[:o["signals"]]
    out_file = os.path.join(ctx.workdir, case.name + ".callgrind")
    if os.path.exists(out_file):
        os.unlink(out_file)
    cfg = ccomm.local_config(ctx.daemon_prio, ctx.cpu("a"))
    with Daemons(ctx.bins, cfg, [(ccomm.LOCAL_NODE, None, ctx.cpu("a"))], ctx.workdir, case.name,
                 no_rt=ctx.no_rt) as d:
        samples = os.path.join(ctx.workdir, case.name + ".samples")
        argv = [vg, "--tool=callgrind", "--callgrind-out-file=" + out_file, "--dump-instr=no"]
        argv += ccomm.latency_argv(ctx.bins, ccomm.LOCAL_NODE, o["rate"], case.seconds, 0, case.name, samples,
                                   send=sigs, recv=sigs, warmup=0.2)
        res = ccomm.run_apps(d, [("app", argv, 0.0)], case.seconds + 90)["app"]
    if not os.path.exists(out_file):
        raise Failed("callgrind wrote no profile")
    calls = callgrind.inclusive_calls(out_file)
    ctx.cost["callgrind_client"] = {"signals": len(sigs), "rate": o["rate"], "cycles": res.get("sent"),
                                    "per_call": callgrind.per_call(calls, CLIENT_FUNCTIONS),
                                    "file": os.path.relpath(out_file, ctx.outdir)}
    return []


RUNNERS = {"ccomm_tput": run_throughput, "large": large.run_large, "ccomm_local": run_local, "ccomm_pp": run_pingpong,
           "ccomm_pair": run_pair, "thesis": run_thesis, "idle": run_idle, "callgrind": run_callgrind,
           "callgrind_client": run_callgrind_client}
