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

This file: what is measured in which order (plan(), SMOKE_CASES), the run's context
(Bench), run_case() and merge_repeats(); how each kind of ccomm case is measured is in
runners.py.
"""

import os
import re
import time
from dataclasses import dataclass, field

from . import ccomm, floors, peers, results, runners, threads
from .ccomm import Failed, Skip
from .floors import Case
from .runners import SPIN_SECONDS

THESIS_RATES = (100, 200, 300, 400, 500, 600, 700, 800, 900, 1000, 10000)
REPEAT = "~%d"  # name suffix of a repeated half; merge_repeats() joins them
PEER_ROUNDS = 5  # rounds of the classes judged against DDS (full run): a round's CPU per value moves
                # by up to 20 % on this shared host, the merge of five by less
# (transport, metric, payload) of those classes: board to board, 1 kHz (peers.pairs()).
PEER_CLASSES = (("udp", "oneway", 8), ("udp", "rtt_half", 8), ("udp", "oneway", 288), ("raw", "rtt_half", 288))
floors.RUNNERS.update(peers.RUNNERS)


@dataclass
class CCase:
    """A ccomm measurement (or a cost measurement); runners.RUNNERS[kind] measures it."""
    name: str
    section: str
    kind: str                 # ccomm_local | ccomm_pair | thesis | idle | callgrind
    seconds: float            # traffic time
    opts: dict = field(default_factory=dict)

    def est_seconds(self):
        return self.seconds * (6 if self.kind == "ccomm_tput" else 1) + {"ccomm_local": 1.2, "ccomm_pp": 1.0, "ccomm_pair": 2.5, "thesis": 2.5,
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

    # ---- today's peers (issue 30), beside the ccomm rows above: board to board Cyclone DDS
    # and Zenoh (one-way and RTT/2, 1 kHz and back to back, 8 / 288 B; throughput at 8 B
    # until loss, each step at least min_values values so the loss limit means something),
    # on one machine iceoryx2 (busy-poll and listener/notifier). peers.py.
    # The 1 kHz classes ccomm is judged in against DDS (peers.pairs()) are measured in
    # rounds, each round ccomm then DDS best-effort then DDS reliable, class by class; each
    # side's rounds are merged into one row (p50 over all samples, CPU per value over all
    # values): the host's drift over the minutes of a run then reaches both sides alike.
    rounds = (1,) if smoke else tuple(range(1, PEER_ROUNDS + 1))

    def round_suffix(k):
        return "" if smoke else REPEAT % k

    def dds_class(q, p, role, suffix):
        o = {"peer": "dds", "reliable": q == "rel"}
        if role == "oneway":
            return Case("dds_%s_oneway_1khz_p%d%s" % (q, p, suffix), "peer_net", "peers", n(2000, 200), p, 1000,
                        dict(o, role="oneway"))
        return Case("dds_%s_rtt_half_1khz_p%d%s" % (q, p, suffix), "peer_net", "peers", n(2000, 200), p, 1000,
                    dict(o, role="rtt", half=True))

    for k in rounds:
        for t, role, p in PEER_CLASSES:
            # One-way 8 B, the class of the thread split (threads.py), also read thread by thread.
            split = {"threads": True} if not smoke and (t, role, p) == PEER_CLASSES[0] else {}
            cases.append(CCase(peers.ccomm_row(t, role, p) + round_suffix(k), "peers", "ccomm_pair", d,
                               dict({"transport": t, "signals": p // 8, "mode": "oneway" if role == "oneway" else "ping",
                                     "style": "block", "rate": 1000}, **split)))
            for q in ("be", "rel"):
                c = dds_class(q, p, role, round_suffix(k))
                c.opts.update(split)
                cases.append(c)
    for peer, qoss in (("dds", ("be", "rel")), ("zenoh", ("udp",))):
        for q in qoss:
            o = {"peer": peer, "reliable": q == "rel"}
            for p in (8, 288):
                if peer != "dds":
                    cases.append(Case("%s_%s_oneway_1khz_p%d" % (peer, q, p), "peer_net", "peers", n(2000, 200), p,
                                      1000, dict(o, role="oneway")))
                    cases.append(Case("%s_%s_rtt_half_1khz_p%d" % (peer, q, p), "peer_net", "peers", n(2000, 200), p,
                                      1000, dict(o, role="rtt", half=True)))
                cases.append(Case("%s_%s_rtt_half_b2b_p%d" % (peer, q, p), "peer_net", "peers", n(5000, 300), p, 0,
                                  dict(o, role="rtt", half=True)))
            cases.append(Case("%s_%s_throughput_p8" % (peer, q), "peer_tput", "peers", 1000, 8, 0,
                              dict(o, step_seconds=secs(0.5, 0.1), min_values=n(2000, 200))))
    for t in ("raw", "udp"):
        cases.append(CCase("ccomm_%s_throughput_p8" % t, "peers", "ccomm_tput", secs(0.5, 0.2),
                           {"transport": t, "min_values": n(2000, 200)}))
    for wait in ("spin", "event"):
        for p in (8, 72, 288):
            cases.append(Case("iox2_%s_b2b_p%d" % (wait, p), "iox2", "peers", n(50000 if wait == "spin" else 10000,
                                                                             1000), p, 0, {"wait": wait}))

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
    "dds_be_oneway_1khz_p8", "dds_rel_rtt_half_1khz_p8", "dds_be_throughput_p8", "ccomm_raw_throughput_p8",
    "ccomm_udp_oneway_block_1khz_p8_vs_dds",
    "cost_idle", "cost_callgrind_single", "cost_callgrind_client", "large_raw_oneway_100hz_p65536",
}


# The CPU counters of a ccomm_pair row (runners.run_pair) and of a peer row (cpu_ns_partner),
# each a sum over its window.
CPU_COUNTERS = ("cpu_ns", "cpu_apps_ns", "cpu_daemons_ns", "window_ns",
                "cpu_ns_whole", "cpu_apps_ns_whole", "cpu_daemons_ns_whole", "cpu_ns_partner")


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
        # CPU per value over every part (each part's own figure weighted by its values), not
        # the first part's alone; each part's figure kept beside it.
        for key in ("cpu_ns_per_value", "cpu_ns_whole_per_value"):
            if all(r.get(key) is not None and r.get("values") for r in parts):
                first[key] = round(sum(r[key] * r["values"] for r in parts) / float(sum(r["values"] for r in parts)))
                first["rep_" + key] = [r[key] for r in parts]
        if all(r.get("values") for r in parts):
            first["values"] = sum(r["values"] for r in parts)
        # The CPU counters behind those figures summed too, so that a counter divided by
        # the merged values is per value over every part (not the first part's over all).
        for key in CPU_COUNTERS:
            if all(r.get(key) is not None for r in parts):
                first[key] = sum(r[key] for r in parts)
        if all(r.get("cpu_daemon_threads") for r in parts):
            th = {}
            for r in parts:
                for role, c in r["cpu_daemon_threads"].items():
                    t = th.setdefault(role, {"run_ns": 0, "times_run": 0})
                    t["run_ns"] += c["run_ns"]
                    t["times_run"] += c["times_run"]
            first["cpu_daemon_threads"] = th
        if any(r.get("threads") for r in parts):
            first["threads"] = [s for r in parts for s in (r.get("threads") or [])]
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
    """("ok", [rows]) or ("skipped"|"failed", reason). A case with opts["threads"] is
    sampled thread by thread while it runs (threads.py): its row's "threads"."""
    if not case.opts.get("threads"):
        return _run_case(ctx, case)
    sampler = threads.Sampler(rate_hz=case.opts.get("rate") or getattr(case, "rate", 0) or 1000).start()
    try:
        status, x = _run_case(ctx, case)
    finally:
        sample = sampler.stop()
    if status == "ok":
        x[0]["threads"] = [sample] if sample else []
    return status, x


def _run_case(ctx, case):
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
        rows = runners.RUNNERS[case.kind](ctx, case)
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
