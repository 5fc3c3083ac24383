#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Many boards on one bridge: N network namespaces, one ccommd and one application each.

  manyboards.py floor --build DIR [--boards 16] [--rate 1000] [--seconds 5] [--transport raw]
  manyboards.py run   --build DIR [--boards 16] [--rate 1000] [--seconds 10] [--transport raw]
                      [--fanout multicast|unicast] [--monitor attr|list|none] [--kill]

floor: bare sockets (bench/manyboards_floor.c), one frame per board per cycle to its own
multicast group, each board receiving from 3 others: can this host move the traffic at all?
run: the ccomm system (signals.xml from config.py); checks counters, frames on the bridge,
and with --kill that consumers flag a killed board's signals stale and fresh again.
Both print a JSON summary as the last line (checks: [[ok, text], ...]); exit 1 when a
check failed. Needs root (namespaces, raw sockets, SCHED_FIFO).
"""

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import config  # noqa: E402
import topology  # noqa: E402

CLK_TCK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid):
    """CPU time of every thread of `pid` so far: the scheduler's run time (schedstat, ns),
    exact, where utime + stime (stat) come in 100 Hz ticks (a 5 s run at 6 % of a CPU is
    30 ticks: 3 % steps); stat where schedstat is missing."""
    try:
        total = 0
        for tid in os.listdir("/proc/%d/task" % pid):
            with open("/proc/%d/task/%s/schedstat" % (pid, tid)) as f:
                total += int(f.read().split()[0])
        return total / 1e9
    except (OSError, ValueError, IndexError):
        with open("/proc/%d/stat" % pid) as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / CLK_TCK  # utime, stime


def wakeups(pid):
    """Voluntary context switches of every thread of `pid` so far: each one a sleep ended by
    a wake-up (the doorbell, a frame, the supervision tick)."""
    total = 0
    try:
        for tid in os.listdir("/proc/%d/task" % pid):
            with open("/proc/%d/task/%s/status" % (pid, tid)) as f:
                for line in f:
                    if line.startswith("voluntary_ctxt_switches"):
                        total += int(line.split()[1])
    except (OSError, ValueError):
        return None
    return total


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2] if xs else None


class Run:
    """A topology plus the processes started in it; everything is removed by close()."""

    def __init__(self, args, n_nodes):
        self.args = args
        self.tag = "mb%d" % os.getpid()
        self.work = args.work or tempfile.mkdtemp(prefix="ccomm-manyboards-")
        os.makedirs(self.work, exist_ok=True)
        self.topo = topology.Topology(self.tag, n_nodes)
        self.procs = []
        self.env = dict(os.environ, CCOMM_SHM_PREFIX="/%s." % self.tag)
        self.checks = []

    def check(self, ok, text):
        self.checks.append([bool(ok), text])
        print("%s - %s" % ("ok" if ok else "not ok", text), flush=True)

    def todo(self, text):
        """Not met, for a reason outside ccomm that the test measured (a saturated host)."""
        self.checks.append([True, "TODO " + text])
        print("ok - %s # TODO" % text, flush=True)

    def spawn(self, i, cmd, log):
        f = open(os.path.join(self.work, log), "w")
        # --pin: every process of board i on CPU i mod CPUs, as a single-core board runs them
        # (the benchmark); unpinned the host spreads one board's threads over all CPUs.
        pin = ["taskset", "-c", str(i % os.cpu_count())] if getattr(self.args, "pin", False) else []
        p = subprocess.Popen(["ip", "netns", "exec", self.topo.ns(i)] + pin + cmd, stdout=f, stderr=subprocess.STDOUT,
                             env=self.env)
        p.log = f.name
        self.procs.append(p)
        return p

    def close(self):
        for p in self.procs:
            if p.poll() is None:
                p.kill()
        for p in self.procs:
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:
                pass
        self.topo.destroy()
        for f in os.listdir("/dev/shm"):
            if f.startswith(self.tag + "."):
                os.unlink(os.path.join("/dev/shm", f))


def bin_path(args, name):
    p = os.path.join(args.build, "bin", name)
    if not os.access(p, os.X_OK):
        sys.exit("manyboards: %s missing (build it: ninja -C %s %s)" % (p, args.build, name))
    return p


# ---- floor ---------------------------------------------------------------------------------
def floor(args, final=True):
    """The floor once; with final=False a loss is not judged but said, and the result says
    retry (main measures again: the floor is the topology's reference, not ccomm)."""
    n = args.boards
    r = Run(args, n)
    prog = bin_path(args, "manyboards_floor")
    try:
        r.topo.create()
        before = r.topo.sent_counts()
        psi0, t0 = cpu_pressure_total(), time.monotonic()
        procs = []
        for j in range(n):
            frm = config.producers_for(j, n, args.consumers)
            cmd = [prog, "--transport", args.transport, "--iface", "eth0", "--id", str(j), "--ip", topology.ip_of(j),
                   "--from", ",".join(map(str, frm)), "--rate", str(args.rate), "--seconds", str(args.seconds)]
            if args.prio:
                cmd = ["chrt", "-f", str(args.prio)] + cmd
            procs.append(r.spawn(j, cmd, "floor-%d.log" % j))
        res = {}
        for j, p in enumerate(procs):
            p.wait(timeout=args.seconds + 30)
            with open(p.log) as f:
                lines = [l for l in f.read().splitlines() if l.startswith("{")]
            res[j] = json.loads(lines[-1]) if lines else None
        psi1, wall = cpu_pressure_total(), time.monotonic() - t0
        pressure = (psi1 - psi0) / 1e6 / wall if psi0 is not None and psi1 is not None else None
        r.check(all(res.values()), "every floor board printed its result")
        if not all(res.values()):
            return r, {}
        exact = all(res[j]["rx"][str(i)] == res[i]["sent"] for j in range(n)
                    for i in config.producers_for(j, n, args.consumers))
        lost = sum(res[j]["lost"] for j in range(n))
        expected = int(args.seconds * args.rate)
        r.check(all(abs(res[j]["sent"] - expected) <= 1 for j in range(n)),
                "every board sent its %d frames (late cycles: %d)" % (expected, sum(res[j]["late_cycles"] for j in res)))
        what = "floor: every frame received by every board that wants it (lost %d)" % lost
        # The floor is plain sockets without ccomm: what it loses on a saturated host (a
        # receiver not scheduled while its socket buffer filled) is the host's, as below.
        if not (exact and lost == 0) and not final:
            print("# %s, CPU pressure %s, late cycles %d: measured again" % (
                what, "%.0f%%" % (100 * pressure) if pressure is not None else "unknown",
                sum(res[j]["late_cycles"] for j in res)), flush=True)
            return r, {"retry": True}
        if not (exact and lost == 0) and pressure is not None and pressure > 0.30:
            r.todo("%s [CPU pressure %.0f%% over the run: host saturated]" % (what, 100 * pressure))
        else:
            r.check(exact and lost == 0, what)
        after = r.topo.sent_counts()
        summary = {"boards": n, "rate": args.rate, "transport": args.transport, "exact": exact and lost == 0,
                   "cpu_pressure": pressure,
                   "p50_ns": median([res[j]["p50_ns"] for j in res]),
                   "cpu_pct_per_board": median([100.0 * res[j]["cpu_s"] / (args.seconds + 0.4) for j in res]),
                   "frames_per_cycle": median([(after[j]["all"] - before[j]["all"]) / max(1, res[j]["sent"])
                                               for j in res])}
        return r, summary
    finally:
        r.close()


# ---- the ccomm system ---------------------------------------------------------------------
def start_daemons(r, cfg_path, nodes):
    ccommd = bin_path(r.args, "ccommd")
    daemons = {}
    for i, name in enumerate(nodes):
        daemons[name] = r.spawn(i, [ccommd, "--node", name, "-c", cfg_path], "ccommd-%s.log" % name)
    wait_segments(r, nodes, daemons)
    return daemons


def wait_segments(r, nodes, daemons, timeout=10.0):
    deadline = time.monotonic() + timeout
    for name in nodes:
        seg = "/dev/shm/%s.%s" % (r.tag, name)
        while not os.path.exists(seg):
            if daemons[name].poll() is not None:
                with open(daemons[name].log) as f:
                    raise RuntimeError("ccommd %s exited: %s" % (name, f.read()[-2000:]))
            if time.monotonic() > deadline:
                raise RuntimeError("ccommd %s: no segment %s after %.0f s" % (name, seg, timeout))
            time.sleep(0.02)


def run_apps(r, nodes, seconds, drain_ms=500):
    app = bin_path(r.args, "manyboards_app")
    # Every app runs the same cycles; board i's cycle starts i/N of a period after board 0's,
    # as independent boards would (all at the same instant would be the worst case).
    start_at = time.monotonic_ns() + 500_000_000
    period_ns = int(1e9 / r.args.rate)
    procs = {}
    for i, name in enumerate(nodes):
        cmd = [app, "--node", name, "--rate", str(r.args.rate), "--seconds", str(seconds), "--drain-ms",
               str(drain_ms), "--start-at", str(start_at + i * period_ns // len(nodes))]
        if r.args.prio:
            cmd += ["--prio", str(r.args.prio)]
        if not getattr(r.args, "latency", True):
            cmd += ["--latency", "0"]
        procs[name] = r.spawn(i, cmd, "app-%s-%d.log" % (name, len(r.procs)))
    return start_at, procs


def collect_apps(procs, timeout):
    out = {}
    for name, p in procs.items():
        p.wait(timeout=timeout)
        with open(p.log) as f:
            lines = [l for l in f.read().splitlines() if l.startswith("{")]
        out[name] = json.loads(lines[-1]) if lines else None
    return out


def receiver_stats(r, nodes):
    """Per node, from its ccommd after the run: what it counted lost on receipt (datagrams the
    kernel dropped at its socket, socket_drops; frames missing from its peers' sequences,
    frames_lost) and per peer (frames received, alive)."""
    out = {}
    for i, name in enumerate(nodes):
        cp = subprocess.run(["ip", "netns", "exec", r.topo.ns(i), bin_path(r.args, "ccomm"), "--node", name,
                             "stats", "--json"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            env=r.env)
        try:
            d = json.loads(cp.stdout)
            out[name] = (d["counters"].get("socket_drops", 0), sum(p["frames_lost"] for p in d.get("peers", [])),
                         {p["name"]: (p["frames_rx"], p["alive"]) for p in d.get("peers", [])})
        except (ValueError, KeyError, TypeError):
            out[name] = None
    return out


def check_receive_work(r, n, nodes, fanout, losses, cycles):
    """Multicast fan-out: a board receives the data of the boards it consumes from, and of a
    board that only consumes from it nothing but heartbeats (it does not join that board's
    group: docs/protocol.md, "Fan-out"), so its receive work follows what it consumes."""
    a = r.args
    if fanout != "multicast" or n < 3 or not all(losses.get(nm) for nm in nodes):
        return
    over = []
    for j, name in enumerate(nodes):
        if name == "mon":
            continue
        sources = {config.board(i) for i in config.producers_for(j, n, a.consumers)}
        sinks = {config.board(i) for i in config.consumers_of(j, n, a.consumers)} - sources
        for peer, (frames, alive) in losses[name][2].items():
            if peer not in sinks:
                continue
            if frames >= cycles // 10 or frames == 0 or not alive:
                over.append("%s got %d frames from %s (alive: %s), which only consumes from it"
                            % (name, frames, peer, alive))
    r.check(not over, "every board hears the boards that only consume from it by their heartbeats alone (alive, "
            "1 to %d frames each, not their data)%s" % (cycles // 10 - 1, "" if not over else ": " + "; ".join(over[:4])))


def cpu_pressure_total():
    """Microseconds some task waited for a CPU (/proc/pressure/cpu), None without PSI."""
    try:
        with open("/proc/pressure/cpu") as f:
            return int(f.readline().split("total=")[1])
    except (OSError, IndexError, ValueError):
        return None


def check_counts(r, res, n, nodes, monitor, fanout, sent_before, sent_after, cycles, pressure=None, losses=None):
    """Phase 1: exact per-signal counters everywhere, frames per cycle on the bridge.

    Exact means: every value a producer's ccommd sent reached every consumer (rx == tx,
    every sequence gap a value the producer coalesced), and values are coalesced
    (replaced by the next cycle's before ccommd sent them) only after a cycle in which the
    application itself woke more than half a period late and so flushed twice in quick succession: that is
    the host descheduling a SCHED_FIFO thread, reported, not a loss of the system."""
    a = r.args
    r.check(all(res.values()), "every board's application ran and reported")
    if not all(res.values()):
        return {}
    prod = {}
    coalesced_total, late_total, unexplained = 0, 0, []
    for name in nodes:
        x = res[name]
        prod.update(x["produced"])
        late_total += x["late_cycles"]
        for sig, v in x["produced"].items():
            coalesced_total += v["coalesced"]
            if v["coalesced"] > x["late_cycles"] or v["tx"] + v["coalesced"] != v["writes"]:
                unexplained.append("%s: tx %d, coalesced %d, writes %d, %d late cycles"
                                   % (sig, v["tx"], v["coalesced"], v["writes"], x["late_cycles"]))
        if x["write_errors"]:
            unexplained.append("%s: %d writes refused" % (name, x["write_errors"]))
    r.check(len(prod) == n * a.signals and all(v["writes"] == cycles and not v["write_errors"] for v in prod.values()),
            "%d signals written %d times each (%d boards x %d), none refused" % (len(prod), cycles, n, a.signals))
    text = ("every write sent or coalesced (tx + coalesced == writes); %d values coalesced, each after an "
            "application cycle that woke more than half a period late (%d such cycles: host scheduling)%s"
            % (coalesced_total, late_total, "" if not unexplained else ": " + "; ".join(unexplained[:4])))
    sent_ok = all(v["tx"] + v["coalesced"] == v["writes"] for v in prod.values())
    if unexplained and sent_ok and pressure is not None and pressure > 0.30:
        # Every coalesced value is accounted for (the consumers' gaps below must equal it),
        # but ccommd itself was late: on a host whose CPUs were this contended that is
        # the host's doing, as in the record suite (docs/testing.md).
        r.todo("%s [CPU pressure %.0f%% over the run: host saturated]" % (text, 100 * pressure))
    else:
        r.check(not unexplained, text)
    wrong, unaccounted, transit_lost = [], 0, 0
    tail_lost = {}  # consumer -> signals whose last values never came, no later frame to count them by
    for j, name in enumerate(nodes):
        if name == "mon":
            want = set(prod)
        else:
            want = {"%s_s%d" % (config.board(i), s) for i in config.producers_for(j, n, a.consumers)
                    for s in range(a.signals)}
        got = res[name]["consumed"]
        if set(got) != want:
            wrong.append("%s consumes %d signals, expected %d" % (name, len(got), len(want)))
        for sig, v in got.items():
            p = prod.get(sig, {"tx": -1, "coalesced": -1})
            # lost <= coalesced: a receiver counts gaps from the first value it got, so a
            # value replaced before the first send is the producer's to count only.
            if v["rx"] != p["tx"] or v["lost"] > p["coalesced"] or v["last_value"] != cycles:
                wrong.append("%s %s rx %d lost %d last %s (sent %d, coalesced %d)" % (
                    name, sig, v["rx"], v["lost"], v["last_value"], p["tx"], p["coalesced"]))
                transit_lost += max(0, p["tx"] - v["rx"])
                # every value sent either arrived or is a gap the consumer's ccommd counted
                if v["rx"] > p["tx"] or v["rx"] + v["lost"] < p["tx"] or v["last_value"] != cycles:
                    unaccounted += 1
                    if v["rx"] <= p["tx"]:
                        tail_lost[name] = tail_lost.get(name, 0) + 1
    text = ("per-signal counters exact on every consumer: rx == values sent, no value lost in transit, last "
            "value %d%s" % (cycles, "" if not wrong else ": " + "; ".join(wrong[:6]) + (" ..." if len(wrong) > 6 else "")))
    # A producer's last values lost on the way have no later frame after them to show the gap:
    # no receiver can count them per signal. Each such consumer's ccommd must have counted
    # the loss on receipt all the same (the kernel's drops at its socket, or frames missing).
    losses = losses or {}
    tails_seen = bool(tail_lost) and unaccounted == sum(tail_lost.values()) and all(
        losses.get(c) and (losses[c][0] > 0 or losses[c][1] > 0) for c in tail_lost)
    if wrong and (not unaccounted or tails_seen) and pressure is not None and pressure > 0.30:
        # As in the record suite: values lost in transit, every one counted lost by the
        # consumer's ccommd, on a host whose CPUs were saturated (ccommd starved).
        tails = "" if not tail_lost else (
            "; the last values of %d signals lost at consumers whose ccommd counted drops on receipt (%s)"
            % (sum(tail_lost.values()), ", ".join("%s: %d socket drops, %d frames lost" % (c, losses[c][0], losses[c][1])
                                                   for c in sorted(tail_lost)[:4])))
        r.todo("%s [%d values lost in transit, all counted lost by the consumers' ccommd%s; CPU pressure %.0f%% "
               "over the run: host saturated]" % (text, transit_lost, tails, 100 * pressure))
    else:
        r.check(not wrong, text)
    if monitor:
        m = res["mon"]["consumed"]
        every = all(v["rx"] == prod[sig]["tx"] for sig, v in m.items() if sig in prod)
        r.check(len(m) == n * a.signals and (every or (wrong and (not unaccounted or tails_seen) and pressure > 0.30)),
                "monitor node received all %d signals of the %d boards, every value sent%s (%s)"
                % (n * a.signals, n, "" if every else " or counted lost (TODO above)",
                   "monitor=\"*\", no consumers= lists it" if monitor == "attr" else "listed in every consumers="))
    # Each cycle's flush leaves as one frame per destination: one to the group (multicast)
    # or one per consumer node (unicast). Frames = values sent of any one signal x that,
    # or fewer: when ccommd ran late, one frame carries two cycles (the older one from the
    # cells' slots, send_path.cpp CatchUp); never more, and at most 1 % merged.
    per_cycle, off, too_many = {}, [], False
    for j, name in enumerate(nodes):
        data = sent_after[j]["data"] - sent_before[j]["data"]
        per_cycle[name] = data / cycles
        if name == "mon":
            dests = 0
            sent = 0
        else:
            dests = 1 if fanout == "multicast" else min(a.consumers, n - 1) + (1 if monitor == "list" else 0)
            sent = res[name]["produced"]["%s_s0" % name]["tx"]
        if data > sent * dests or data < 0.99 * sent * dests:
            off.append("%s %d frames for %d cycles sent x %d" % (name, data, sent, dests))
            too_many = too_many or data > sent * dests
    want = 1 if fanout == "multicast" else min(a.consumers, n - 1) + (1 if monitor == "list" else 0)
    text = ("data frames counted on the bridge = %d per producing board per cycle sent, or one for "
            "two cycles after a late round (%s; median "
            "%.4f per cycle)%s" % (want, fanout, median([per_cycle[config.board(i)] for i in range(n)]),
                                   "" if not off else ": " + "; ".join(off[:6])))
    if off and not too_many and pressure is not None and pressure > 0.30:
        # Fewer frames than cycles only: a ccommd the saturated host held back for several
        # cycles sends them in one frame (every value still counted above); never more.
        r.todo("%s [CPU pressure %.0f%% over the run: host saturated]" % (text, 100 * pressure))
    else:
        r.check(not off, text)
    hb = {name: sent_after[j]["heartbeat"] - sent_before[j]["heartbeat"] for j, name in enumerate(nodes)}
    return {"data_frames_per_cycle": median(list(per_cycle[config.board(i)] for i in range(n))),
            "heartbeats_max": max(hb.values()), "coalesced": coalesced_total, "late_app_cycles": late_total}


def check_kill(r, res, n, nodes, victim, t_kill, t_dead, t_restart, pressure=None):
    """Phase 2: the victim's signals go stale on every consumer within stale_after_ms
    (+ tolerance) of the kill and fresh again after the restart; no other signal blinks.
    The kill is judged from t_dead (its ccommd reaped): this harness is not real-time, and
    between its clock reading t_kill and the SIGKILL landing it can be descheduled (CI saw
    11 ms), while the victim still sends. The contract itself is judged exactly by what each
    reader saw: the value's age at its first stale read (stale_after_ms + the reader's delay)."""
    a = r.args
    tol_ns = a.stale_tolerance_ms * 1_000_000
    limit = a.stale_after_ms * 1_000_000 + tol_ns
    vname = config.board(victim)
    late, never_fresh, false_alarm, delays, ages, back = [], [], [], [], [], []
    for name in nodes:
        for s, v in res[name]["consumed"].items():
            if s.startswith(vname + "_"):
                first_stale = [t for t in v["stale_at"] if t >= t_kill]
                fresh_after = [t for t in v["fresh_at"] if t >= t_restart]
                age = v.get("max_stale_age_ns", 0)
                if not first_stale or first_stale[0] - t_dead > limit or age > limit:
                    late.append("%s %s %s" % (name, s, "%.1f ms after the kill, age %.1f ms at the first stale read"
                                              % ((first_stale[0] - t_dead) / 1e6, age / 1e6)
                                              if first_stale else "never stale"))
                else:
                    delays.append(first_stale[0] - t_dead)
                    ages.append(age)
                if not fresh_after or v["to_fresh"] != v["to_stale"]:
                    never_fresh.append("%s %s" % (name, s))
                else:
                    back.append(fresh_after[0] - t_restart)
            elif v["to_stale"] and name != vname:
                false_alarm.append("%s %s x%d" % (name, s, v["to_stale"]))
    saturated = pressure is not None and pressure > 0.30
    # On a saturated host (the 17 ccommd and 17 apps alone reach 89-94% CPU pressure on 2
    # CPUs) the kill timing is the scheduler's: such a miss is reported as TODO with the
    # measured pressure, as the counter checks do; unexplained misses under it stay open
    # (docs/testing.md, "manyboards").
    check_or_todo = (lambda ok, text: r.todo(text + " [CPU pressure %.0f%% over the kill run: host saturated]"
                                             % (100 * pressure)) if not ok and saturated else r.check(ok, text))
    check_or_todo(not late and bool(delays), "consumers flag %s's signals stale within stale_after_ms %d + %d ms of the kill "
                  "(%d signals on time; slowest %.1f ms after its ccommd was reaped, %.1f ms after the kill was decided; "
                  "ages at the first stale read %.1f-%.1f ms)%s"
                  % (vname, a.stale_after_ms, a.stale_tolerance_ms, len(delays), max(delays) / 1e6 if delays else -1,
                     (max(delays) + t_dead - t_kill) / 1e6 if delays else -1, min(ages) / 1e6 if ages else -1,
                     max(ages) / 1e6 if ages else -1, "" if not late else ": " + "; ".join(late[:6])))
    check_or_todo(not never_fresh and bool(back), "fresh again after the restart (slowest %.0f ms after ccommd restarted)%s"
                  % (max(back) / 1e6 if back else -1, "" if not never_fresh else ": " + "; ".join(never_fresh[:6])))
    text = "no other board's signal went stale meanwhile%s" % ("" if not false_alarm else ": " + "; ".join(false_alarm[:6]))
    if false_alarm and saturated:
        # A consumer's ccommd starved for more than stale_after_ms reads frames that waited in
        # its socket; their values are aged by that wait (peer clock floor) and really are
        # stale. Measured, outside ccomm: as for the counters above.
        r.todo("%s [CPU pressure %.0f%% over the kill run: host saturated]" % (text, 100 * pressure))
    else:
        r.check(not false_alarm, text)
    return {"stale_delay_ms_max": max(delays) / 1e6 if delays else None,
            "fresh_after_restart_ms_max": max(back) / 1e6 if back else None}


def system(args):
    n = args.boards
    monitor = None if args.monitor == "none" else args.monitor
    text, nodes = config.generate(n, args.transport, args.fanout, monitor, consumers=args.consumers,
                                  signals=args.signals, stale_after_ms=args.stale_after_ms,
                                  daemon_prio=args.daemon_prio)
    r = Run(args, len(nodes))
    summary = {"boards": n, "rate": args.rate, "transport": args.transport, "fanout": args.fanout}
    try:
        cfg = os.path.join(r.work, "signals.xml")
        with open(cfg, "w") as f:
            f.write(text)
        cp = subprocess.run([bin_path(args, "ccommd"), "--check", cfg], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
        r.check(cp.returncode == 0, "ccommd --check accepts the generated %d-node signals.xml%s"
                % (len(nodes), "" if cp.returncode == 0 else ": " + cp.stdout.strip()[-500:]))
        if cp.returncode != 0:
            return r, summary
        r.topo.create()
        daemons = start_daemons(r, cfg, nodes)
        time.sleep(0.5)  # heartbeats: every peer alive before traffic
        cycles = int(round(args.seconds * args.rate))
        sent0 = r.topo.sent_counts()
        cpu0 = {nm: cpu_seconds(p.pid) for nm, p in daemons.items()}
        wake0 = {nm: wakeups(p.pid) for nm, p in daemons.items()}
        psi0 = cpu_pressure_total()
        t0 = time.monotonic()
        _, apps = run_apps(r, nodes, args.seconds)
        res = collect_apps(apps, args.seconds + 30)
        wall = time.monotonic() - t0
        psi1 = cpu_pressure_total()
        pressure = (psi1 - psi0) / 1e6 / wall if psi0 is not None and psi1 is not None else None
        summary["cpu_pressure"] = pressure
        cpu = {nm: cpu_seconds(p.pid) - cpu0[nm] for nm, p in daemons.items()}
        wake1 = {nm: wakeups(p.pid) for nm, p in daemons.items()}
        sent1 = r.topo.sent_counts()
        losses = receiver_stats(r, nodes)
        summary.update(check_counts(r, res, n, nodes, monitor, args.fanout, sent0, sent1, cycles, pressure, losses))
        check_receive_work(r, n, nodes, args.fanout, losses, cycles)
        boards = [config.board(i) for i in range(n)]
        if all(res.values()):
            if args.latency:
                summary["p50_ns"] = median([res[b]["p50_ns"] for b in boards])
                summary["p99_ns"] = median([res[b]["p99_ns"] for b in boards])
            summary["late_cycles"] = sum(res[b]["late_cycles"] for b in boards)
            summary["app_cpu_pct_per_board"] = median([100.0 * res[b]["cpu_s"] / wall for b in boards])
        summary["cpu_pct_per_board"] = median([100.0 * cpu[b] / wall for b in boards])
        if all(wake0.get(b) is not None and wake1.get(b) is not None for b in boards) and cycles:
            summary["wakeups_per_cycle_per_board"] = median([(wake1[b] - wake0[b]) / float(cycles) for b in boards])
        summary["cpu_pct_max_board"] = max(100.0 * cpu[b] / wall for b in boards)
        if monitor:
            summary["cpu_pct_monitor"] = 100.0 * cpu["mon"] / wall
        for nm, p in daemons.items():
            if p.poll() is not None:
                r.check(False, "ccommd %s still running after the run (exit %s)" % (nm, p.returncode))
        if args.kill:
            victim = 1 % n
            vname = config.board(victim)
            # The apps run on well past the restart: on a loaded machine reaping, the 1 s pause
            # and the restarted ccommd's start-up can take seconds (CI saw the apps end before
            # the restarted ccommd was up, so "fresh again" could not be seen).
            kill_seconds = 7.0
            psi0, t0 = cpu_pressure_total(), time.monotonic()
            start_at, apps = run_apps(r, nodes, kill_seconds)
            time.sleep(max(0.0, (start_at - time.monotonic_ns()) / 1e9) + 1.5)
            t_kill = time.monotonic_ns()
            daemons[vname].send_signal(signal.SIGKILL)
            daemons[vname].wait()
            t_dead = time.monotonic_ns()
            time.sleep(1.0)
            t_restart = time.monotonic_ns()
            daemons[vname] = r.spawn(victim, [bin_path(args, "ccommd"), "--node", vname, "-c", cfg],
                                     "ccommd-%s-restarted.log" % vname)
            wait_segments(r, [vname], daemons)
            res = collect_apps(apps, kill_seconds + 30)
            psi1, wall = cpu_pressure_total(), time.monotonic() - t0
            kill_pressure = (psi1 - psi0) / 1e6 / wall if psi0 is not None and psi1 is not None else None
            summary["kill_cpu_pressure"] = kill_pressure
            r.check(all(res.values()), "every application ran through the kill and restart")
            if all(res.values()):
                summary.update(check_kill(r, res, n, nodes, victim, t_kill, t_dead, t_restart, kill_pressure))
        return r, summary
    finally:
        r.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=("floor", "run"))
    ap.add_argument("--build", required=True, help="build tree with bin/ccommd, bin/manyboards_app, bin/manyboards_floor")
    ap.add_argument("--boards", type=int, default=16)
    ap.add_argument("--rate", type=float, default=1000, help="cycles per second of every board (default 1000)")
    ap.add_argument("--seconds", type=float, default=10)
    ap.add_argument("--transport", choices=("raw", "udp"), default="raw")
    ap.add_argument("--fanout", choices=("multicast", "unicast"), default="multicast")
    ap.add_argument("--monitor", choices=("attr", "list", "none"), default="attr",
                    help='monitor node: monitor="*" (attr), named in every consumers= (list), or none')
    ap.add_argument("--consumers", type=int, default=3, help="each signal goes to the next K boards (default 3)")
    ap.add_argument("--signals", type=int, default=4, help="signals per board (default 4)")
    ap.add_argument("--stale-after-ms", type=int, default=50)
    ap.add_argument("--stale-tolerance-ms", type=int, default=10)
    ap.add_argument("--kill", action="store_true", help="then kill -9 one board's ccommd and restart it")
    ap.add_argument("--prio", type=int, default=70, help="SCHED_FIFO of the applications (0: none)")
    ap.add_argument("--daemon-prio", type=int, default=80, help="SCHED_FIFO of ccommd (<realtime priority>)")
    ap.add_argument("--no-latency", dest="latency", action="store_false",
                    help="applications without their receiver thread: no latency figures, less load")
    ap.add_argument("--work", help="directory for logs and the generated signals.xml (kept)")
    ap.add_argument("--pin", action="store_true",
                    help="run each board's processes on one CPU (board i on CPU i mod CPUs), as a single-core board")
    args = ap.parse_args()
    if os.geteuid() != 0:
        print("manyboards: needs root (network namespaces, raw sockets)", file=sys.stderr)
        return 4
    topology.sweep_stale()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))
    if args.mode == "floor":
        # A floor that lost frames is measured again, up to three times in all (CI: 826
        # frames lost by bare sockets at 25 % CPU pressure beside the image build, while
        # ccomm then lost none): its last try is judged.
        for attempt in (1, 2, 3):
            r, summary = floor(args, final=attempt == 3)
            if not summary.get("retry"):
                break
    else:
        r, summary = system(args)
    summary["checks"] = r.checks
    summary["work"] = r.work
    print(json.dumps(summary))
    return 0 if r.checks and all(ok for ok, _ in r.checks) else 1


if __name__ == "__main__":
    sys.exit(main())
