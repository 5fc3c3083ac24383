# SPDX-License-Identifier: Apache-2.0
"""Today's peers (issue 30), measured in the same run as ccomm:

  dds     Cyclone DDS (Debian's libddsc), bench/dds_pingpong.c, board to board
  zenoh   Zenoh peer-to-peer over UDP (crate pinned in bench/peers/zenoh), board to board
  iox2    iceoryx2 (crate pinned in bench/peers/iceoryx2), on one machine

Every peer program speaks the floors' command line and prints their one JSON line
(bench_common.h), plus cpu_ns (utime+stime of every thread of that process over its
measured window) and values (messages delivered in that window); the partner (echo,
source) prints its own cpu_ns on stderr. A row's cpu_ns_per_value is the sum over both
processes / values. The Rust peers are built by build_rust() into CCOMM_PEERS_CACHE
(default ~/.cache/ccomm-peers), once; a peer that is not built is reported as skipped
with the reason, never dropped silently.
"""

import json
import os
import subprocess

from . import procs
from .procs import Failed, Skip

HERE = os.path.dirname(os.path.abspath(__file__))
BENCH = os.path.dirname(HERE)
RUST_PEERS = {"iox2": ("iceoryx2", "iox2-pingpong"), "zenoh": ("zenoh", "zenoh-pingpong")}
# values per second offered by the throughput sweep; 0 = back to back (the last step).
# ccomm-latency sends periodically, so ccomm's sweep ends at the last non-zero rate.
THROUGHPUT_RATES = (1000, 2000, 5000, 10000, 20000, 50000, 100000, 0)
# A step "without loss" loses at most this fraction: on a shared 2-CPU host a receiver
# descheduled for two periods loses a value (keep-last 1, ccomm's last-value state
# signals) at any rate, and a strict zero would measure the host's load, not the peer.
LOSS_LIMIT = 0.001


def lossy(row):
    n = (row.get("count") or 0) + (row.get("lost") or 0)
    return not n or (row.get("lost") or 0) > LOSS_LIMIT * n


def sweep(measure, rates):
    """measure(rate) -> row at each rate until one is lossy; the summary row is the last
    step without loss (values_per_s_lossfree), with every step in throughput_steps."""
    best, steps, row = None, [], None
    for rate in rates:
        row = measure(rate)
        steps.append({"offered_hz": rate, "received": row.get("count"), "lost": row.get("lost"),
                      "rx_values_per_s": row.get("rx_values_per_s"), "p50_ns": row.get("p50_ns"),
                      "cpu_ns_per_value": row.get("cpu_ns_per_value")})
        if lossy(row):
            break
        best = row
    out = dict(best or row)
    out["throughput_steps"] = steps
    out["metric"] = "one_way"
    if best is None:
        out["values_per_s_lossfree"] = 0
    else:
        out["values_per_s_lossfree"] = best.get("rx_values_per_s") if not best["rate_hz"] else best["rate_hz"]
    bad = [s for s in steps if lossy({"count": s["received"], "lost": s["lost"]})]
    out["values_per_s_at_loss"] = (bad[0]["rx_values_per_s"] or bad[0]["offered_hz"]) if bad else None
    return out
ZENOH_PORT = 47910


def cache_dir():
    return os.environ.get("CCOMM_PEERS_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "ccomm-peers")


def rust_binary(peer):
    d, exe = RUST_PEERS[peer]
    return os.path.join(cache_dir(), d, "release", exe)


def build_rust(peer, log):
    """cargo build --release --locked of one peer into the cache (a no-op when it is up
    to date). Returns the binary, or raises Skip with the reason."""
    d, _ = RUST_PEERS[peer]
    src = os.path.join(BENCH, "peers", d)
    env = dict(os.environ, CARGO_TARGET_DIR=os.path.join(cache_dir(), d))
    env.setdefault("CARGO_BUILD_JOBS", "1")
    try:
        with open(log, "w") as f:
            cp = subprocess.run(["nice", "-n", "19", "cargo", "build", "--release", "--locked"], cwd=src, env=env,
                                stdout=f, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    except FileNotFoundError:
        raise Skip("cargo not found (rustup's, 1.89 or later: Debian 12's is too old for iceoryx2)")
    if cp.returncode != 0:
        raise Skip("cargo build of bench/peers/%s failed (see %s)" % (d, log))
    return rust_binary(peer)


def partner_cpu(log):
    """cpu_ns printed by the echo or source (a JSON line on stderr) or None."""
    try:
        with open(log, errors="replace") as f:
            for line in reversed(f.read().splitlines()):
                if line.startswith("{") and "cpu_ns" in line:
                    return json.loads(line)
    except (OSError, ValueError):
        pass
    return None


def _add_cpu(row, other):
    """cpu_ns_per_value over both processes."""
    if other is None or row.get("cpu_ns") is None or not row.get("values"):
        return row
    row["cpu_ns_partner"] = other.get("cpu_ns")
    row["cpu_ns_per_value"] = round((row["cpu_ns"] + other["cpu_ns"]) / float(row["values"]))
    return row


# ---- how each network peer is told where the other is ----

def dds_config(peer_ip, ifname="eth0", tag="ccbench"):
    """CYCLONEDDS_URI: one interface, no multicast, discovery by unicast to the other
    side and a discovery tag of this run: nothing leaves the veth pair, nothing of
    another run (or another DDS user of the machine) is seen."""
    return ("<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"%s\"/></Interfaces>"
            "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
            "<Tag>%s</Tag><Peers><Peer address=\"%s\"/></Peers></Discovery></Domain></CycloneDDS>" % (
                ifname, tag, peer_ip))


def _net_argv(ctx, case, side):
    """(argv prefix for side a or b) of a network peer case."""
    ns = ctx.netns()
    peer = case.opts["peer"]
    if peer == "dds":
        exe = ctx.prog("dds_pingpong")
        other = ns.IP_B if side == "a" else ns.IP_A
        pre = ["env", "CYCLONEDDS_URI=" + dds_config(other), exe]
        if case.opts.get("reliable"):
            pre.append("--reliable")
        return pre
    exe = _rust_prog(ctx, "zenoh")
    # b listens, a connects: peer mode, multicast scouting off (bench/peers/zenoh).
    return [exe, "--listen" if side == "b" else "--connect", "udp/%s:%d" % (ns.IP_B, ZENOH_PORT)]


def _rust_prog(ctx, peer):
    key = "rust:" + peer
    if key not in ctx.programs:
        exe = rust_binary(peer)
        if not os.path.exists(exe):
            raise Skip("not built (a cold cargo build takes 10-60 min on 2 cores, more than CI has): "
                       "`scripts/bench --peers rust` builds bench/peers/%s into CCOMM_PEERS_CACHE (~/.cache/ccomm-peers)"
                       % RUST_PEERS[peer][0])
        ctx.programs[key] = exe
    return ctx.programs[key]


def _timeout(case):
    return 40 + 3 * case.est_seconds()


def run_net_peer(ctx, case):
    """Ping-pong (RTT/2) or one-way (sink in b measures) between the namespaces."""
    ns = ctx.netns()
    common = ctx.common(case)
    if case.opts["role"] == "rtt":
        echo_log = ctx.log(case, "echo")
        row = procs.ping_with_echo(
            ns.wrap("b", _net_argv(ctx, case, "b") + ["--role", "echo", "--idle-ms", "30000"] + ctx.side_opts("b")),
            echo_log, ns.wrap("a", _net_argv(ctx, case, "a") + ["--role", "ping"] + common + ctx.side_opts("a")),
            _timeout(case), ctx.log(case, "ping"), echo_exit=10)
        return _add_cpu(row, partner_cpu(echo_log))
    return _one_way(ctx, case, common)


def _one_way(ctx, case, common):
    ns = ctx.netns()
    src_log = ctx.log(case, "source")
    row = procs.source_to_sink(
        ns.wrap("b", _net_argv(ctx, case, "b") + ["--role", "sink", "--idle-ms", "5000"] + common + ctx.side_opts("b")),
        ctx.log(case, "sink"),
        ns.wrap("a", _net_argv(ctx, case, "a") + ["--role", "source"] + common[:-2] + ctx.side_opts("a")),
        src_log, _timeout(case), sink_exit=20)
    return _add_cpu(row, partner_cpu(src_log))


def run_throughput(ctx, case):
    """8 B values one way at rising offered rates (THROUGHPUT_RATES) until loss."""
    def measure(rate):
        count = int(max(case.opts["min_values"], (rate or 100000) * case.opts["step_seconds"]))
        sub = type(case)(case.name + "_%d" % rate, case.kind, case.group, count, case.payload, rate,
                         dict(case.opts, role="oneway"))
        return _one_way(ctx, sub, ctx.common(sub))
    row = sweep(measure, THROUGHPUT_RATES)
    row["name"] = case.name
    return row


def run_iox2(ctx, case):
    """iceoryx2 ping-pong on one machine (RTT/2), busy-poll or listener/notifier."""
    exe = _rust_prog(ctx, "iox2")
    svc = "ccb-%d-%s" % (os.getpid(), case.name)
    w = ["--wait", case.opts["wait"], "--service", svc]
    echo_log = ctx.log(case, "echo")
    row = procs.ping_with_echo([exe, "--role", "echo", "--payload", str(case.payload)] + w + ctx.side_opts("b"),
                               echo_log, [exe, "--role", "ping", "--half"] + w + ctx.common(case) + ctx.side_opts("a"),
                               20 + 3 * case.est_seconds(), ctx.log(case, "ping"), echo_exit=10)
    return _add_cpu(row, partner_cpu(echo_log))


RUNNERS = {"peer_net": run_net_peer, "peer_tput": run_throughput, "iox2": run_iox2}


# ---- targets and the report section ----

def ccomm_row(transport, metric, payload, vs="dds"):
    """The ccomm row a board-to-board peer class is judged against. Against DDS: the rows
    measured in rounds alternating with DDS's (suite.PEER_CLASSES), named _vs_dds; against
    another peer, the board-to-board section's row."""
    base = "ccomm_%s_%s_block_1khz_p%d" % (transport, metric, payload)
    return base + "_vs_dds" if vs == "dds" else base


# (peer row, ccomm row it is judged against, class). Board to board the UDP peers are
# judged against ccomm over UDP (same transport); 288 B RTT/2 only exists over raw.
def pairs():
    out = []
    for peer, qoss in (("dds", ("be", "rel")), ("zenoh", ("udp",))):
        for q in qoss:
            for p in (8, 288):
                out.append(("%s_%s_oneway_1khz_p%d" % (peer, q, p), ccomm_row("udp", "oneway", p, peer),
                            "board to board, one-way, 1 kHz"))
                out.append(("%s_%s_rtt_half_1khz_p%d" % (peer, q, p),
                            ccomm_row("udp" if p == 8 else "raw", "rtt_half", p, peer),
                            "board to board, RTT/2, 1 kHz"))
    for p in (8, 288):
        out.append(("iox2_spin_b2b_p%d" % p, "ccomm_pp_state_spin_call_b2b_p%d" % p, "on-target, busy-poll"))
    out.append(("iox2_event_b2b_p8", "ccomm_pp_state_block_call_b2b_p8", "on-target, blocking"))
    return out


def checks(R, check):
    """Target lines: ccomm p50 below the peer's, and ccomm CPU per value below the
    peer's, for every pair; a missing row is n/a with the row named, never dropped."""
    out = []
    for pname, cname, cls in pairs():
        pr, cr = R.get(pname), R.get(cname)
        for what, key in (("p50", "p50_ns"), ("CPU per value", "cpu_ns_per_value")):
            text = "peers (%s): ccomm %s below %s's (`%s` vs `%s`)" % (cls, what, pname.split("_")[0], cname, pname)
            if not pr or not cr or pr.get(key) is None or cr.get(key) is None:
                miss = [n for n, r in ((pname, pr), (cname, cr)) if not r or r.get(key) is None]
                ck = check(text, None, "n/a (missing: %s)" % ", ".join("`%s`" % m for m in miss))
                ck["rows"] = (cname, pname, key)
                out.append(ck)
                continue
            ok = cr[key] < pr[key]
            detail = "ccomm %.2f µs vs %.2f µs (%.2fx)" % (cr[key] / 1e3, pr[key] / 1e3, cr[key] / float(pr[key]))
            if not ok:
                detail += ", over by %.2f µs" % ((cr[key] - pr[key]) / 1e3)
            ck = check(text, ok, detail, "peers")
            ck["rows"] = (cname, pname, key)
            out.append(ck)
    return out


def _us(ns):
    return "-" if ns is None else "%.2f" % (ns / 1e3)


def section(R, meta, problems):
    """'## 2a. Today's peers' of docs/performance.md: every peer row (or why it is
    missing) beside the ccomm row it is judged against."""
    peer_rows = [r for r in R.rows if r.get("section") == "peers" and not r["name"].startswith("ccomm_")]
    missing = [p for p in problems if p["name"].split("_")[0] in ("dds", "zenoh", "iox2")
               or "throughput" in p["name"]]
    if not peer_rows and not missing:
        return []
    L = ["## 2a. Today's peers: Cyclone DDS, Zenoh, iceoryx2 (issue 30)\n"]
    L.append("Measured in the same run as the ccomm rows beside them, on the same CPUs with the same payloads "
             "(load average at start %s, at end %s). Board to board: the two namespaces joined by veth, "
             "Cyclone DDS %s (Debian's libddsc, `bench/dds_pingpong.c`: keep-last 1, best-effort `be` or "
             "reliable `rel`, waitset receive, unicast discovery on eth0, no multicast) and Zenoh (crate pinned in "
             "`bench/peers/zenoh`, peer mode over UDP, multicast scouting off, one explicit endpoint). On one "
             "machine: iceoryx2 (crate pinned in `bench/peers/iceoryx2`), busy-poll and listener/notifier, "
             "RTT/2. One-way rows share one clock (the namespaces share CLOCK_MONOTONIC). CPU per value: utime + "
             "stime of every process involved (peers: both processes, every thread, over their measured window; "
             "ccomm board to board the same: each application over its measured window, its send loop or its first "
             "value received to its last, and both ccommds' threads over the span of the two windows, sampled every "
             "20 ms; the on-target ping-pong rows count both processes' whole lives) / "
             "values delivered (a round trip delivers two). Throughput: 8 B one way at %s values/s offered "
             "(`0` = back to back; ccomm-latency sends periodically, so ccomm's sweep ends at the last non-zero "
             "rate), stopping at the first step that loses more than %g%% of the values (on this shared host a "
             "receiver descheduled for two periods loses one at any rate, with keep-last 1 as with ccomm's "
             "last-value state signals); the row is the last step within that.\n" % (" ".join(meta.get("loadavg_start") or []), " ".join(meta.get("loadavg_end") or []),
                                  (meta.get("versions") or {}).get("libddsc0debian", ""),
                                  ", ".join(str(r) for r in THROUGHPUT_RATES), LOSS_LIMIT * 100))
    L.append("What CI covers: `scripts/bench --smoke` (the `bench` step of scripts/test) runs Cyclone DDS (one-way, "
             "reliable RTT/2, throughput) and ccomm's throughput sweep: `dds_pingpong` builds with the tree from "
             "Debian's packages in seconds. The Rust peers are not in the smoke run; a full run measures them when "
             "`scripts/bench --peers rust` has built them into the cache (or a build is already there): their cold "
             "builds (iceoryx2 0.10.0: 85 crates, "
             "Zenoh 1.10.2 with only its UDP transport: 346) took 22 and 25 minutes on this loaded 2-core machine "
             "at nice 19, beyond CI's time. zenoh-pico is not measured: it is packaged neither by Debian 12 nor on crates.io, and "
             "this project builds nothing from a source checkout.\n")
    head = ["peer row", "p50 µs", "p99 µs †", "lost", "CPU/value µs", "ccomm row", "ccomm p50 µs",
            "ccomm CPU/value µs"]
    lines = []
    seen = set()
    for pname, cname, cls in pairs():
        pr, cr = R.get(pname), R.get(cname)
        if not pr:
            continue
        seen.add(pname)
        lines.append(["`%s`" % pname, "**%s**" % _us(pr["p50_ns"]), _us(pr["p99_ns"]), pr["lost"],
                      _us(pr.get("cpu_ns_per_value")), "`%s`" % cname, "**%s**" % _us(cr["p50_ns"]) if cr else "-",
                      _us(cr.get("cpu_ns_per_value")) if cr else "-"])
    for r in peer_rows:
        if r["name"] in seen or "throughput" in r["name"]:
            continue
        lines.append(["`%s`" % r["name"], "**%s**" % _us(r["p50_ns"]), _us(r["p99_ns"]), r["lost"],
                      _us(r.get("cpu_ns_per_value")),
                      "(no ccomm row of this kind: ccomm_pingpong runs 8 and 288 B busy-polling, 8 B blocking)"
                      if r["name"].startswith("iox2") else
                      "(no ccomm row of this kind: ccomm-latency sends periodically, never back to back)", "-", "-"])
    if lines:
        L.append("| " + " | ".join(head) + " |")
        L.append("|" + "|".join(["---"] + ["---:"] * 4 + ["---", "---:", "---:"]) + "|")
        L += ["| " + " | ".join(str(x) for x in l) + " |" for l in lines]
        L.append("")
    split = [R.get(n) for n in (ccomm_row("udp", "oneway", 8), "dds_be_oneway_1khz_p8", "dds_rel_oneway_1khz_p8")]
    if any(r and r.get("threads") for r in split):
        L.append("Where the CPU of one value goes, one-way 8 B at 1 kHz over UDP, thread by thread (`bench/benchlib/"
                 "threads.py`): in each round of these rows every thread of the programs was read from /proc once the "
                 "traffic was steady and again a window later (run time from schedstat; user and system as the "
                 "kernel's 100 Hz ticks, coarse; wake-ups = voluntary context switches, each one a sleep and a "
                 "wake-up). Board A (CPU 0) sends, board B (CPU 1) receives. Per value the sender wrote in the "
                 "windows. ccomm's path has one hand-off more than DDS's on the sending board (the application's "
                 "`ccomm_flush()` wakes ccommd's send thread, which makes the `sendto`); DDS sends from the "
                 "application's own thread and, like ccommd on board B, wakes a receive thread per packet.\n")
        from . import threads
        L += threads.table([r for r in split if r])
        L.append("History of these comparisons (issue 38): when the issue was filed (dcb2aca, a full run on this "
                 "machine, load 0.58) ccomm's CPU per value was over Cyclone DDS's in all eight classes: one-way "
                 "8 B 118.1 µs vs 94.0 µs (1.26x best-effort, 1.37x reliable), one-way 288 B 128.8 vs 96.7 µs "
                 "(1.33x, 1.52x reliable), RTT/2 1.04-1.09x. Counted over the measured window as the peers' "
                 "CPU is, not over the programs' whole lives (11cbdb3), ccomm-latency without the thread a "
                 "sending side does not need (9666531: its idle `ccomm_wait()` was woken by each of its own "
                 "writes), no `recvfrom` per tick for ptp4l's answers off a PTP network (fc4569b), supervision "
                 "on its own schedule (148236e) and a 1 s socket wait (ab82469): below DDS in 5 of 8 classes at "
                 "6ec71d9, 7 of 8 at 3773fd0 (one run each, the ccomm rows minutes before DDS's). From 6646eaa "
                 "on, each class is judged on rounds alternating ccomm, DDS best-effort and DDS reliable, merged "
                 "(three, then five: suite.PEER_ROUNDS, each round's figure kept as `rep_cpu_ns_per_value`); "
                 "from this version on, the supervision no longer ticks every 10 ms while this node's signals "
                 "are written (the summary reads a produced signal's age off its newest value), which took "
                 "board A's ccommd main thread from 100 wake-ups a second to 10.\n")
    tput = [r for r in R.rows if "throughput" in r["name"]]
    if tput:
        L.append("Throughput at 8 B, one way (steps: offered values/s -> lost). Not like for like in one respect: "
                 "Zenoh's default subscriber queues every sample (a FIFO channel), so a late receiver catches up; "
                 "Cyclone DDS (keep-last 1) and ccomm's state signals keep only the newest value, so a receiver "
                 "descheduled for two periods loses one.\n")
        L.append("| row | values/s without loss | delivered at the first lossy step | p50 µs there | CPU/value µs "
                 "| steps |")
        L.append("|---|---:|---:|---:|---:|---|")
        for r in tput:
            steps = ", ".join("%s: %s lost" % (s["offered_hz"] or "b2b", s["lost"]) for s in r.get("throughput_steps", []))
            L.append("| `%s` | **%s** | %s | %s | %s | %s |" % (
                r["name"], r.get("values_per_s_lossfree"), r.get("values_per_s_at_loss") or "-", _us(r["p50_ns"]),
                _us(r.get("cpu_ns_per_value")), steps))
        L.append("")
    if missing:
        L.append("Peers that did not run (reported, not dropped):\n")
        L += ["- `%s`: %s" % (p["name"], p["reason"]) for p in missing]
        L.append("")
    return L


def why(R, check):
    """A missed peer target explained from the run's own numbers: where ccomm's one-way
    time went (ccomm-latency --stages) or how its CPU splits between the applications and
    the daemons, against the peer's."""
    cname, pname, key = check["rows"]
    c, p = R.get(cname), R.get(pname)
    if key == "p50_ns":
        g = c.get("stages")
        if g:
            return ("ccomm's path is app -> ccommd -> wire -> ccommd -> app, the peer's library writes the socket "
                    "itself: in `%s` the write -> far ccommd has the frame part took p50 %s µs and far ccommd -> "
                    "application %s µs (ccomm-latency --stages), against %s µs for the whole of `%s`." % (
                        cname, _us(g.get("upstream_p50_ns")), _us(g.get("last_hop_p50_ns")), _us(p["p50_ns"]), pname))
        if c.get("floor_p50_ns"):
            return ("`%s` interleaved the bare shared-memory floor (one cache line handed over between the same two "
                    "processes) in blocks of %s round trips: floor p50 %s µs, ccomm %s µs, so ccomm's own cost is "
                    "%s µs; `%s` took %s µs, %s µs above that floor (measured minutes apart, in the same run)." % (
                        cname, c.get("block"), _us(c["floor_p50_ns"]), _us(c["p50_ns"]),
                        _us(c["p50_ns"] - c["floor_p50_ns"]), pname, _us(p["p50_ns"]),
                        _us(p["p50_ns"] - c["floor_p50_ns"])))
        return ("`%s` has no stage timestamps (RTT/2 rows are not split); its one-way rows above are." % cname)
    if c.get("cpu_ns") is not None:
        v = float(c.get("values") or 1)
        whole = ""
        if c.get("cpu_ns_whole_per_value") is not None and c.get("cpu_basis") != "whole lives":
            whole = (" Counted over the applications' whole lives instead (start-up, attach, memory locking and "
                     "the leads between them included, as this table did before), `%s` took %s µs per value "
                     "(%s in the applications, %s in ccommd)." % (
                         cname, _us(c["cpu_ns_whole_per_value"]), _us(c.get("cpu_apps_ns_whole", 0) / v),
                         _us(c.get("cpu_daemons_ns_whole", 0) / v)))
        split = ""
        th = c.get("cpu_daemon_threads") or {}
        if th:
            split = " By ccommd thread (both daemons together, per value): %s." % "; ".join(
                "%s %s µs, run %.2f times" % (role, _us(th[role]["run_ns"] / v), th[role]["times_run"] / v)
                for role in ("send", "receive", "main") if role in th)
        return ("Per value, `%s` spent %s µs in its two application processes and %s µs in ccommd (both daemons, "
                "every thread: send and receive threads, the supervision tick and heartbeats included), "
                "each counted over the measured window as the peer's are (the sender's send loop, the receiver "
                "from its first value to its last; the daemons over the span of both); `%s` spent %s + %s µs in "
                "its two processes. ccommd's share is the daemon design's price: the peer's library sends from "
                "the application's own thread.%s%s" % (
                    cname, _us(c.get("cpu_apps_ns", 0) / v), _us(c.get("cpu_daemons_ns", 0) / v), pname,
                    _us((p.get("cpu_ns") or 0) / float(p.get("values") or 1)),
                    _us((p.get("cpu_ns_partner") or 0) / float(p.get("values") or 1)), split, whole))
    return ""
