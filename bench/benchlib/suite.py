# SPDX-License-Identifier: Apache-2.0
"""The plan of scripts/bench: floors, peers and ccomm, measured in one run.

Sections (rows carry "section" and a plot "group"):
  ontarget  app -> app through shared memory on one board: ccomm state and event
            signals vs the shared-memory floors (spinning, futex, eventfd) and iceoryx
  b2b       board -> board, two namespaces joined by veth: ccomm raw/UDP vs the raw
            AF_PACKET and UDP floors and LCM
  thesis    the thesis' single-signal and setup-simulation experiments, 100..1000 Hz
            and 10 kHz, event-driven and periodic
  cost      ccommd CPU time when idle, and instructions per forwarded signal (callgrind)

Receive styles are kept apart: "block" = the receiver sleeps until woken (ccomm_wait,
futex, eventfd, recv, WaitSet), "spin" = it busy-polls. Each ccomm row names its
style and the floor rows it is compared with.
"""

import os
import re
import shutil
import time
from dataclasses import dataclass, field

from . import ccomm, floors, large, procs, results
from .ccomm import Daemons, Failed, Skip
from .floors import Case

THESIS_RATES = (100, 200, 300, 400, 500, 600, 700, 800, 900, 1000, 10000)
# A spinning SCHED_FIFO thread is throttled after 0.95 s of every second
# (sched_rt_runtime_us): a spinning receiver's whole life (lead, warm-up, samples and
# ccomm-latency's 0.2 s tail) stays below that.
SPIN_SECONDS = 0.4
SPIN_WARMUP = 0.15
SPIN_LEAD = 0.05
REPEAT = "~%d"  # name suffix of a repeated half; merge_repeats() joins them


@dataclass
class CCase:
    """A ccomm measurement (or a cost measurement); run() returns a list of rows."""
    name: str
    section: str
    kind: str                 # ccomm_local | ccomm_pair | thesis | idle | callgrind
    seconds: float            # traffic time
    opts: dict = field(default_factory=dict)

    def est_seconds(self):
        return self.seconds + {"ccomm_local": 1.2, "ccomm_pp": 1.0, "ccomm_pair": 2.5, "thesis": 2.5,
                               "idle": 1.5, "callgrind": 12.0, "callgrind_client": 5.0}.get(self.kind, 1.0)


def thesis_duration(rate, smoke):
    """Traffic time per thesis point: >= 2000 samples where that fits in 5 s, >= 2 s."""
    if smoke:
        return 0.6
    return min(5.0, max(2.0, 2000.0 / rate))


def plan(smoke=False, rates=None, scale=1.0):
    """[Case | CCase] in run order."""
    def n(full, quick):
        return max(50, int((quick if smoke else full) * scale))

    def secs(full, quick):
        return max(0.4, (quick if smoke else full) * scale)

    cases = []
    # ---- on-target ----
    # The headline: ccomm's hand-off measured exactly like the busy-read floor (two
    # processes, back-to-back ping-pong, RTT/2), and the floor itself interleaved with it
    # in blocks of 1000 round trips between the same two processes: the target is judged
    # on the median over block pairs of ccomm / floor (ccomm_pingpong --floor-shm), so a
    # change of the host's placement of the two virtual CPUs between runs cannot sway it.
    # ccomm in both clock modes: a clock reading in every read and write, or one per loop
    # iteration (ccomm_set_time, a control loop's usage).
    for p in (8, 288):
        cases.append(Case("shm_spin_b2b_p%d" % p, "shm", "ontarget", n(100000, 3000), p, 0, {"mode": "spin"}))
    for p in (8, 288):
        for kind in (("state", "event") if p == 8 else ("state",)):
            for clock in ("call", "cycle"):
                cases.append(CCase("ccomm_pp_%s_spin_%s_b2b_p%d" % (kind, clock, p), "ontarget", "ccomm_pp",
                                   0.5, {"kind": kind, "payload": p, "wait": "spin", "clock": clock,
                                         "count": n(60000, 3000), "interleave": True}))
    for p in (8, 288):
        cases.append(Case("shm_futex_b2b_p%d" % p, "shm", "ontarget", n(20000, 500), p, 0, {"mode": "futex"}))
    for kind in ("state", "event"):
        cases.append(CCase("ccomm_pp_%s_block_call_b2b_p8" % kind, "ontarget", "ccomm_pp", 1.0,
                           {"kind": kind, "payload": 8, "wait": "block", "clock": "call", "count": n(20000, 500)}))
    cases.append(Case("shm_eventfd_b2b_p8", "shm", "ontarget", n(20000, 500), 8, 0, {"mode": "eventfd"}))
    cases.append(Case("shm_futex_1khz_p8", "shm", "ontarget", n(3000, 200), 8, 1000, {"mode": "futex"}))
    for p in (8, 72, 288):
        cases.append(Case("iox_spin_b2b_p%d" % p, "iox", "ontarget", n(50000, 2000), p, 0, {"wait": "spin"}))
    for p in (8, 72, 288):
        cases.append(Case("iox_waitset_b2b_p%d" % p, "iox", "ontarget", n(10000, 500), p, 0, {"wait": "waitset"}))
    cases.append(Case("iox_waitset_1khz_p8", "iox", "ontarget", n(3000, 200), 8, 1000, {"wait": "waitset"}))
    for style in ("spin", "block"):
        d = SPIN_SECONDS if style == "spin" else secs(3.0, 0.6)
        for p in (8, 72, 288):
            cases.append(CCase("ccomm_shm_state_%s_1khz_p%d" % (style, p), "ontarget", "ccomm_local", d,
                               {"style": style, "signals": p // 8, "event": False, "rate": 1000}))
        cases.append(CCase("ccomm_shm_event_%s_1khz_p8" % style, "ontarget", "ccomm_local", d,
                           {"style": style, "signals": 1, "event": True, "rate": 1000}))

    # ---- board -> board ----
    # Each ccomm case runs right after the floor it is compared with: on a shared
    # machine the conditions drift, and the ratio should see the same ones.
    # The headline pairs (ccomm one-way against the plain-socket floor) alternate, and
    # each side's halves are merged into one row: four alternations and a closing floor
    # half (floor / ccomm / ... / ccomm / floor). Each ccomm half sits between two floor
    # halves and the report judges it against their mean, so a host that drifts during
    # the run cancels out to first order; the median of the four ratios is what a burst
    # of load during one of them cannot sway.
    d = secs(2.0, 0.6)

    def oneway_floor(t, p, suffix):
        return Case("net_%s_oneway_1khz_p%d%s" % (t, p, suffix), "net", "b2b", n(1000, 300), p, 1000,
                    {"transport": t, "role": "oneway"})

    for t in ("raw", "udp"):
        for p in (8, 288):
            for rep in ((1, 2, 3, 4) if not smoke else (1,)):
                suffix = "" if smoke else REPEAT % rep
                cases.append(oneway_floor(t, p, suffix))
                cases.append(CCase("ccomm_%s_oneway_block_1khz_p%d%s" % (t, p, suffix), "b2b", "ccomm_pair",
                                   d,
                                   {"transport": t, "signals": p // 8, "mode": "oneway", "style": "block",
                                    "rate": 1000}))
                if p == 288:
                    # The same 288 bytes as one signal (a 36-element array): one entry per
                    # frame instead of 36, so per-signal and per-byte costs show apart.
                    cases.append(CCase("ccomm_%s_oneway_block_1khz_p288arr%s" % (t, suffix), "b2b", "ccomm_pair",
                                       d, {"transport": t, "signals": 1, "count": 36, "mode": "oneway",
                                           "style": "block", "rate": 1000}))
            if not smoke:
                cases.append(oneway_floor(t, p, REPEAT % 5))  # the closing floor half
            if t == "raw" and p == 8:
                cases.append(CCase("ccomm_raw_oneway_spin_1khz_p8", "b2b", "ccomm_pair", SPIN_SECONDS,
                                   {"transport": "raw", "signals": 1, "mode": "oneway", "style": "spin",
                                    "rate": 1000}))
    cases.append(Case("lcm_netns_rtt_half_1khz_p8", "lcm", "b2b", n(4000, 300), 8, 1000,
                      {"placement": "netns", "half": True}))
    for t in ("raw", "udp"):
        cases.append(Case("net_%s_rtt_half_1khz_p8" % t, "net", "b2b", n(4000, 300), 8, 1000,
                          {"transport": t, "role": "rtt", "half": True}))
        cases.append(CCase("ccomm_%s_rtt_half_block_1khz_p8" % t, "b2b", "ccomm_pair", d,
                           {"transport": t, "signals": 1, "mode": "ping", "style": "block", "rate": 1000}))
    cases.append(Case("lcm_netns_rtt_half_1khz_p288", "lcm", "b2b", n(4000, 300), 288, 1000,
                      {"placement": "netns", "half": True}))
    cases.append(CCase("ccomm_raw_rtt_half_block_1khz_p288", "b2b", "ccomm_pair", d,
                       {"transport": "raw", "signals": 36, "mode": "ping", "style": "block", "rate": 1000}))

    # ---- the thesis experiments ----
    rates = rates or THESIS_RATES
    for exp in ("single", "setup"):
        for mode in ("event", "periodic"):
            for r in rates:
                cases.append(CCase("thesis_%s_%s_%s" % (exp, mode, rate_tag(r)), "thesis", "thesis",
                                   thesis_duration(r, smoke) * scale,
                                   {"exp": exp, "mode": mode, "rate": r}))
        # 10 kHz once more with busy-polling receivers: what a wake-up costs at 100 µs.
        cases.append(CCase("thesis_%s_event_spin_10khz" % exp, "thesis", "thesis", SPIN_SECONDS,
                           {"exp": exp, "mode": "event", "rate": 10000, "style": "spin"}))

    # ---- large values: 1 KiB (one frame) against 64 KiB (47 fragments), 100 Hz ----
    for t in ("raw", "udp"):
        for count in (128, 8192):
            cases.append(CCase("large_%s_oneway_100hz_p%d" % (t, 8 * count), "large", "large", secs(4.0, 0.8),
                               {"transport": t, "count": count, "rate": 100}))

    # ---- cost ----
    cases.append(CCase("cost_idle", "cost", "idle", secs(3.0, 0.5), {}))
    for exp in ("single", "setup"):
        cases.append(CCase("cost_callgrind_%s" % exp, "cost", "callgrind", secs(3.0, 0.8),
                           {"exp": exp, "rate": 200}))
    cases.append(CCase("cost_callgrind_client", "cost", "callgrind_client", secs(2.0, 0.8),
                       {"signals": 36, "rate": 500}))
    if smoke:
        cases = [c for c in cases if c.name in SMOKE_CASES]
    return cases


# The smoke run: one case of every kind of measurement, so none of them can rot.
SMOKE_CASES = {
    "shm_spin_b2b_p8", "shm_futex_b2b_p8", "ccomm_pp_state_spin_cycle_b2b_p8", "ccomm_pp_event_spin_call_b2b_p8",
    "ccomm_pp_state_block_call_b2b_p8", "shm_futex_1khz_p8", "iox_spin_b2b_p8", "iox_waitset_b2b_p8",
    "ccomm_shm_state_spin_1khz_p8", "ccomm_shm_state_block_1khz_p8", "ccomm_shm_event_block_1khz_p8",
    "net_raw_oneway_1khz_p8", "net_udp_oneway_1khz_p8", "net_raw_rtt_half_1khz_p8", "lcm_netns_rtt_half_1khz_p8",
    "ccomm_raw_oneway_block_1khz_p8", "ccomm_udp_oneway_block_1khz_p8", "ccomm_raw_oneway_spin_1khz_p8",
    "ccomm_raw_oneway_block_1khz_p288arr",
    "ccomm_raw_rtt_half_block_1khz_p8",
    "thesis_single_event_1khz", "thesis_setup_event_1khz", "thesis_setup_periodic_1khz",
    "thesis_setup_event_spin_10khz",
    "cost_idle", "cost_callgrind_single", "cost_callgrind_client", "large_raw_oneway_100hz_p65536",
}


def merge_repeats(rows, outdir):
    """Join the halves of repeated cases (NAME~1, NAME~2) into one row NAME: samples
    concatenated from the raw files, counters summed, statistics recomputed."""
    groups, order = {}, []
    for r in rows:
        m = re.match(r"^(.*)~(\d+)$", r["name"])
        if not m:
            order.append(r)
            continue
        base = m.group(1)
        if base not in groups:
            groups[base] = []
            order.append(base)
        groups[base].append(r)
    out = []
    for x in order:
        if isinstance(x, dict):
            out.append(x)
            continue
        parts = groups[x]
        samples, lost = [], 0
        for r in parts:
            if r.get("raw"):
                samples += [ns for _, ns in results.load_raw(os.path.join(outdir, r["raw"])) if ns >= 0]
            lost += r["lost"]
        first = dict(parts[0])
        rep_p50 = [r.get("p50_ns") for r in parts]
        for k in list(first):
            if k in results.SCHEMA_FIELDS:
                del first[k]
        first.pop("raw", None)
        raw_rel = os.path.join("raw", x + ".tsv")
        with open(os.path.join(outdir, raw_rel), "w") as f:
            for i, ns in enumerate(samples):
                f.write("%d\t%d\n" % (i, ns))
        if first.get("sent") is not None:
            first["sent"] = sum(r.get("sent") or 0 for r in parts)
        if isinstance(first.get("wire"), dict):
            w = {}
            for r in parts:
                for k, v in (r.get("wire") or {}).items():
                    w[k] = w.get(k, 0) + v
            first["wire"] = w
            if first.get("sent"):
                first["frames_per_cycle"] = round(w.get("data_frames", 0) / float(first["sent"]), 3)
        if all(r.get("stages_raw") for r in parts):
            rel = os.path.join("raw", x + ".stages.tsv")
            with open(os.path.join(outdir, rel), "w") as f:
                for r in parts:
                    with open(os.path.join(outdir, r["stages_raw"])) as g:
                        f.write(g.read())
            first["stages_raw"] = rel
            first["stages"] = ccomm.stages(os.path.join(outdir, rel))
        first["seconds"] = round(sum(r.get("seconds", 0) for r in parts), 2)
        first["merged_from"] = [r["name"] for r in parts]
        first["rep_p50_ns"] = rep_p50
        out.append(results.row_from_samples(x, parts[0]["transport"], parts[0]["payload_bytes"],
                                            parts[0]["rate_hz"], samples, lost, raw=raw_rel, **first))
    return out


def rate_tag(r):
    return "%gkhz" % (r / 1000.0) if r >= 1000 else "%ghz" % r


def select(cases, pattern):
    if not pattern:
        return cases
    rx = re.compile(pattern)
    return [c for c in cases if rx.search(c.name)]


# ---------------------------------------------------------------------------------------

class Bench(floors.Context):
    """floors.Context plus the ccomm programs and the daemon priority."""

    def __init__(self, programs, ccomm_bins, outdir, cpus, prio, prefix, smoke, daemon_prio=None):
        super().__init__(programs, outdir, cpus=cpus, prio=prio, prefix=prefix)
        self.bins = ccomm_bins
        self.smoke = smoke
        self.workdir = os.path.join(outdir, "ccomm")
        os.makedirs(self.workdir, exist_ok=True)
        # ccommd's threads above the applications, as on a board (<realtime priority=>).
        self.daemon_prio = daemon_prio or (min(99, prio + 10) if prio else 80)
        self.no_rt = prio == 0
        self.cost = {}      # extra data for the report (idle, callgrind)

    def cpu(self, side):
        if not self.cpus:
            return None
        return self.cpus[0] if side == "a" else self.cpus[1]

    def need(self, *names):
        for n in names:
            if n not in self.bins:
                raise Skip("%s not built" % n)


def run_case(ctx, case):
    """("ok", [rows]) or ("skipped"|"failed", reason)."""
    if isinstance(case, Case):
        status, x = floors.run_case(ctx, case)
        if status == "failed":
            # A floor or peer program that fails once (e.g. iox_pingpong hanging on exit)
            # gets one more try; the row says so. ccomm's own cases are never retried.
            first = x
            status, x = floors.run_case(ctx, case)
            if status == "ok":
                x["retried"] = first
        if status == "ok":
            x["section"] = case.group
            if case.opts.get("half"):
                x["metric"] = "rtt_half"
            return status, [x]
        return status, x
    t0 = time.monotonic()
    try:
        rows = RUNNERS[case.kind](ctx, case)
    except Skip as e:
        return "skipped", str(e)
    except Failed as e:
        return "failed", str(e)
    except (OSError, ValueError, KeyError) as e:
        return "failed", "%s: %s" % (type(e).__name__, e)
    for r in rows:
        r.setdefault("section", case.section)
        r.setdefault("group", case.section)
        r["kind"] = case.kind
        r["seconds"] = round(time.monotonic() - t0, 2)
    return "ok", rows


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
        echo = procs.start_background(exe + ["--role", "echo"] + ctx.side_opts("b"),
                                      os.path.join(ctx.workdir, case.name + ".echo.log"))
        try:
            argv = exe + ["--role", "ping", "--half", "--name", case.name, "--count", str(o["count"]),
                          "--warmup", "1000", "--dump", os.path.join(ctx.rawdir, case.name + ".tsv")] + \
                ctx.side_opts("a")
            row = procs.run_measurement(argv, 60, os.path.join(ctx.workdir, case.name + ".ping.log"))
        finally:
            procs.stop(echo)
            procs.forget(echo)
            if floor_shm and os.path.exists("/dev/shm" + floor_shm):
                os.unlink("/dev/shm" + floor_shm)  # the ping removes it; not after a failure
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
        if o["mode"] == "ping":
            apps = [("b", _app(ctx, d, "b", names[1], rate, dur + 0.6, case.name + "-echo", sb, mode="echo"), 0.0),
                    ("a", _app(ctx, d, "a", names[0], rate, dur, case.name, sa, mode="ping"), 0.3)]
        else:
            # The receiver starts first and ends last (a spinning one only just).
            lead = SPIN_LEAD if spin else 0.3
            apps = [("b", _app(ctx, d, "b", names[1], rate, dur + 2 * lead, case.name, sb, spin=spin, warmup=warm),
                     0.0),
                    ("a", _app(ctx, d, "a", names[0], rate, dur, case.name + "-src", sa, warmup=warm), lead)]
        res = ccomm.run_apps(d, apps, dur + 30)
        after = _snapshot(d, names)
    dirn = ccomm.delta_stats(before, after, names[0], names[1])
    extra = dict(style=o["style"], signals=k, elements=count, signal_kind="state", wire=dirn, sent=res["a"]["sent"],
                 frames_per_cycle=_ratio(dirn["data_frames"], res["a"]["sent"]),
                 command=res["b"]["argv"] if o["mode"] == "oneway" else res["a"]["argv"],
                 daemon_command=d.argv[names[0]])
    if o["mode"] == "ping":
        row = ccomm.samples_row(case.name, o["transport"], 8 * k * count, rate, res["a"], sa, ctx.rawdir,
                                metric="rtt_half", **extra)
    else:
        row = ccomm.samples_row(case.name, o["transport"], 8 * k * count, rate, res["b"], sb, ctx.rawdir,
                                **extra)
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

        sub = CCase(tag, case.section, case.kind, 0)
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
            per[n] = {"ir": ccomm.callgrind_total(files[n]), "tx": sig["tx"], "rx": sig["rx"],
                      "file": os.path.relpath(files[n], ctx.outdir)}
        out[phase] = per
    res = {"exp": o["exp"], "rate": o["rate"], "seconds": case.seconds, "nodes": {}}
    for n in names:
        t, i = out["traffic"][n], out["idle"][n]
        handled = t["tx"] + t["rx"]
        calls = ccomm.callgrind_calls(os.path.join(ctx.outdir, t["file"]))
        res["nodes"][n] = {"ir_traffic": t["ir"], "ir_idle": i["ir"], "tx": t["tx"], "rx": t["rx"],
                           "ir_per_signal": round((t["ir"] - i["ir"]) / handled, 1) if handled else None,
                           "per_call": ccomm.per_call(calls, DAEMON_FUNCTIONS), "file": t["file"]}
    ctx.cost.setdefault("callgrind", {})[o["exp"]] = res
    return []


# What a forwarded signal and a frame cost inside ccommd, by function (inclusive Ir per call).
DAEMON_FUNCTIONS = [
    ("send: collect one signal from shared memory and encode it", "Daemon::CollectSignal("),
    ("send: add one entry to the frame (wire encoding)", "FrameWriter::Add("),
    ("send: finish and send one frame (user part of sendto)", "Daemon::FlushPeer("),
    ("receive: validate one frame and store its entries", "Daemon::HandleFrame("),
    ("receive: one transport receive call (user part of recvfrom)", "RawRecv("),
    ("supervision tick (every 10 ms)", "Daemon::Supervise("),
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
    calls = ccomm.callgrind_calls(out_file)
    ctx.cost["callgrind_client"] = {"signals": len(sigs), "rate": o["rate"], "cycles": res.get("sent"),
                                    "per_call": ccomm.per_call(calls, CLIENT_FUNCTIONS),
                                    "file": os.path.relpath(out_file, ctx.outdir)}
    return []


RUNNERS = {"large": large.run_large, "ccomm_local": run_local, "ccomm_pp": run_pingpong, "ccomm_pair": run_pair, "thesis": run_thesis, "idle": run_idle,
           "callgrind": run_callgrind, "callgrind_client": run_callgrind_client}
