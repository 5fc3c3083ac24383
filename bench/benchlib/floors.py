# SPDX-License-Identifier: Apache-2.0
"""The floor and peer measurements: what ccomm's numbers are read against.

Each Case is one result row. Cases of one kind share their set-up (one netns pair
for every network case, one private iox-roudi for every iceoryx case), made when
the first such case runs and removed by Context.close().

Metrics: shared-memory cases (shm_*, iox_*) report RTT/2, the one-way estimate their
own literature uses; network and LCM cases report the round trip, and the *_oneway
cases a true one-way time (sender and receiver read the same clock: one machine,
two namespaces).
"""

import os
import re
import shutil
import time
from dataclasses import dataclass, field

from . import procs
from .procs import Failed, Skip

PROGRAMS = ("shm_floor", "net_floor", "lcm_pingpong", "iox_pingpong", "dds_pingpong")


@dataclass
class Case:
    name: str
    kind: str          # shm | net | lcm | iox
    group: str         # plot group: "shm" (same-host shared memory) or "net"
    count: int
    payload: int = 8
    rate: float = 0.0  # Hz, 0 = back-to-back
    opts: dict = field(default_factory=dict)

    def est_seconds(self):
        if self.rate:
            return self.count / self.rate
        per = {"shm": 60e-6, "net": 40e-6, "lcm": 120e-6, "iox": 30e-6}.get(self.kind, 100e-6)
        if self.opts.get("mode") == "spin" or self.opts.get("wait") == "spin":
            per = 1e-6
        return self.count * per


def plan(smoke=False, payloads=(8, 72, 288), rate=1000.0, scale=1.0):
    """The default set of cases. smoke: a few seconds in all; otherwise about two minutes."""
    def n(full, quick):
        return max(50, int((quick if smoke else full) * scale))

    p0 = payloads[0]
    tag = lambda r: "b2b" if not r else ("%gkhz" % (r / 1000.0) if r >= 1000 else "%ghz" % r)
    cases = [
        Case("shm_spin_b2b_p%d" % p0, "shm", "shm", n(200000, 5000), p0, 0, {"mode": "spin"}),
        Case("shm_futex_b2b_p%d" % p0, "shm", "shm", n(30000, 1000), p0, 0, {"mode": "futex"}),
        Case("shm_eventfd_b2b_p%d" % p0, "shm", "shm", n(30000, 1000), p0, 0, {"mode": "eventfd"}),
        Case("shm_futex_%s_p%d" % (tag(rate), p0), "shm", "shm", n(3000, 200), p0, rate, {"mode": "futex"}),
    ]
    for t in ("raw", "udp"):
        for p in payloads:
            cases.append(Case("net_%s_rtt_%s_p%d" % (t, tag(rate), p), "net", "net", n(5000, 200), p, rate,
                              {"transport": t, "role": "rtt"}))
        cases.append(Case("net_%s_rtt_b2b_p%d" % (t, p0), "net", "net", n(20000, 1000), p0, 0,
                          {"transport": t, "role": "rtt"}))
        cases.append(Case("net_%s_oneway_%s_p%d" % (t, tag(rate), p0), "net", "net", n(5000, 200), p0, rate,
                          {"transport": t, "role": "oneway"}))
    for p in payloads:
        cases.append(Case("lcm_netns_rtt_%s_p%d" % (tag(rate), p), "lcm", "net", n(5000, 200), p, rate,
                          {"placement": "netns"}))
    cases.append(Case("lcm_netns_rtt_b2b_p%d" % p0, "lcm", "net", n(5000, 500), p0, 0, {"placement": "netns"}))
    cases.append(Case("lcm_local_rtt_%s_p%d" % (tag(rate), p0), "lcm", "net", n(3000, 200), p0, rate,
                      {"placement": "local"}))
    for p in payloads:
        cases.append(Case("iox_spin_b2b_p%d" % p, "iox", "shm", n(100000, 2000), p, 0, {"wait": "spin"}))
    for p in payloads:
        cases.append(Case("iox_waitset_b2b_p%d" % p, "iox", "shm", n(20000, 1000), p, 0, {"wait": "waitset"}))
    cases.append(Case("iox_waitset_%s_p%d" % (tag(rate), p0), "iox", "shm", n(3000, 200), p0, rate,
                      {"wait": "waitset"}))
    return cases


def find_programs(bin_dirs):
    """{program: path} for the bench programs found in the first dir that has each."""
    found = {}
    for prog in PROGRAMS:
        for d in bin_dirs:
            path = os.path.join(d, prog)
            if os.path.isfile(path) and os.access(path, os.X_OK):
                found[prog] = path
                break
    return found


def _other_roudi_running():
    """True if an iox-roudi we did not start is running (we would collide with it)."""
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open("/proc/%s/comm" % pid) as f:
                if f.read().strip() == "iox-roudi":
                    return True
        except OSError:
            continue
    return False


ROUDI_CONFIG = """\
# Private RouDi configuration for scripts/bench-floors: small pools, enough for
# ping-pong with payloads up to 16 KiB.
[general]
version = 1

[[segment]]

[[segment.mempool]]
size = 128
count = 256

[[segment.mempool]]
size = 1024
count = 256

[[segment.mempool]]
size = 16384
count = 64
"""


class Context:
    """Shared state of one run: programs, output dirs, CPU placement, set-ups."""

    def __init__(self, programs, outdir, cpus=None, prio=0, warmup=100, prefix="ccb"):
        self.programs = programs
        self.outdir = outdir
        self.rawdir = os.path.join(outdir, "raw")
        self.logdir = os.path.join(outdir, "logs")
        os.makedirs(self.rawdir, exist_ok=True)
        os.makedirs(self.logdir, exist_ok=True)
        self.cpus = cpus  # (A, B) or None
        self.prio = prio
        self.warmup = warmup
        self.prefix = prefix
        self._netns = None
        self._netns_error = None
        self._roudi = None
        self._roudi_error = None

    # ---- common arguments ----
    def prog(self, name):
        if name not in self.programs:
            raise Skip("%s not built (its library was not found at build time)" % name)
        return self.programs[name]

    def side_opts(self, side):
        o = []
        if self.cpus:
            o += ["--cpu", str(self.cpus[0] if side == "a" else self.cpus[1])]
        if self.prio:
            o += ["--prio", str(self.prio)]
        return o

    def common(self, case):
        raw = os.path.join(self.rawdir, case.name + ".tsv")
        # opts["half"]: report RTT/2 (ping-pong peers compared with one-way figures).
        half = ["--half"] if case.opts.get("half") else []
        return ["--name", case.name, "--payload", str(case.payload), "--rate", "%g" % case.rate,
                "--count", str(case.count), "--warmup", str(self.warmup)] + half + ["--dump", raw]

    def log(self, case, what):
        return os.path.join(self.logdir, "%s.%s.log" % (case.name, what))

    # ---- shared set-ups ----
    def netns(self):
        if self._netns_error:
            raise self._netns_error
        if self._netns is None:
            pair = procs.NetnsPair(self.prefix)
            try:
                pair.__enter__()
            except (Skip, Failed) as e:
                self._netns_error = e
                raise
            self._netns = pair
        return self._netns

    def roudi(self):
        if self._roudi_error:
            raise self._roudi_error
        if self._roudi is None:
            try:
                self._roudi = self._start_roudi()
            except (Skip, Failed) as e:
                self._roudi_error = e
                raise
        return self._roudi

    def _start_roudi(self):
        exe = shutil.which("iox-roudi")
        if not exe:
            raise Skip("iox-roudi not installed (Debian package: iceoryx)")
        if _other_roudi_running():
            raise Skip("another iox-roudi is running; not touching it")
        d = os.path.join(self.outdir, "iox")
        os.makedirs(d, exist_ok=True)
        cfg = os.path.join(d, "roudi.toml")
        with open(cfg, "w") as f:
            f.write(ROUDI_CONFIG)
        # -m off: no process monitoring, nothing to kill our partner behind our back.
        p = procs.start_background([exe, "-c", cfg, "-m", "off", "-l", "warning"], os.path.join(d, "roudi.log"))
        if not procs.wait_for_text(p.log_path, "RouDi is ready for clients", 15, p):
            procs.stop(p, grace=0)
            procs.forget(p)
            with open(p.log_path, errors="replace") as f:
                tail = " | ".join(f.read().strip().splitlines()[-3:])
            raise Failed("iox-roudi did not come up: " + tail)
        return p

    def close(self):
        if self._roudi is not None:
            # SIGTERM is RouDi's normal shutdown; it removes its shared memory itself.
            try:
                self._roudi.terminate()
                self._roudi.wait(timeout=10)
            except Exception:
                pass
            procs.stop(self._roudi, grace=0)
            procs.forget(self._roudi)
            self._roudi = None
        procs.stop_all()
        if self._netns is not None:
            self._netns.__exit__(None, None, None)
            self._netns = None


# ---- runners, one per kind ----

def _timeout(case):
    # Shared-memory peers finish in about a second; a hung one should not cost 30 s.
    base = 10 if case.kind in ("shm", "iox") else 30
    return base + 3 * case.est_seconds()


def run_shm(ctx, case):
    argv = [ctx.prog("shm_floor"), "--mode", case.opts["mode"], "--half"] + ctx.common(case)
    if ctx.cpus:
        argv += ["--cpu", "%d,%d" % ctx.cpus]
    if ctx.prio:
        argv += ["--prio", str(ctx.prio)]
    return procs.run_measurement(argv, _timeout(case), ctx.log(case, "run"))


def run_net(ctx, case):
    exe = ctx.prog("net_floor")
    ns = ctx.netns()
    t = case.opts["transport"]
    if t == "raw":
        link_a = ["--transport", "raw", "--if", "eth0", "--dst", ns.MAC_B]
        link_b = ["--transport", "raw", "--if", "eth0"]
    else:
        link_a = ["--transport", "udp", "--peer", "%s:47900" % ns.IP_B]
        link_b = ["--transport", "udp", "--bind", "%s:47900" % ns.IP_B]
    if case.opts["role"] == "rtt":
        return procs.ping_with_echo(
            ns.wrap("b", [exe, "--role", "echo", "--idle-ms", "60000"] + link_b + ctx.side_opts("b")),
            ctx.log(case, "echo"),
            ns.wrap("a", [exe, "--role", "ping"] + link_a + ctx.common(case) + ctx.side_opts("a")),
            _timeout(case), ctx.log(case, "ping"))
    # One-way: the sink (ns b) measures and prints the row; the source (ns a) only sends.
    return procs.source_to_sink(
        ns.wrap("b", [exe, "--role", "sink"] + link_b + ctx.common(case) + ctx.side_opts("b")), ctx.log(case, "sink"),
        ns.wrap("a", [exe, "--role", "source"] + link_a + ctx.common(case)[:-2] + ctx.side_opts("a")),
        ctx.log(case, "source"), _timeout(case))


def run_lcm(ctx, case):
    exe = ctx.prog("lcm_pingpong")
    ns = ctx.netns()
    echo_side = "b" if case.opts["placement"] == "netns" else "a"
    row = procs.ping_with_echo(ns.wrap(echo_side, [exe, "--role", "echo"] + ctx.side_opts("b")),
                               ctx.log(case, "echo"),
                               ns.wrap("a", [exe, "--role", "ping"] + ctx.common(case) + ctx.side_opts("a")),
                               _timeout(case), ctx.log(case, "ping"))
    row["placement"] = case.opts["placement"]
    return row


def run_iox(ctx, case):
    exe = ctx.prog("iox_pingpong")
    ctx.roudi()
    w = ["--wait", case.opts["wait"]]
    return procs.ping_with_echo([exe, "--role", "echo"] + w + ctx.side_opts("b"), ctx.log(case, "echo"),
                                [exe, "--role", "ping", "--half"] + w + ctx.common(case) + ctx.side_opts("a"),
                                _timeout(case), ctx.log(case, "ping"))


# kind -> runner(ctx, case) returning a schema row; scripts/bench adds its ccomm kinds here.
RUNNERS = {"shm": run_shm, "net": run_net, "lcm": run_lcm, "iox": run_iox}


def run_case(ctx, case):
    """Run one case: ("ok", row) or ("skipped"|"failed", reason)."""
    t0 = time.monotonic()
    try:
        row = RUNNERS[case.kind](ctx, case)
    except Skip as e:
        return "skipped", str(e)
    except Failed as e:
        return "failed", str(e)
    row["group"] = case.group
    row["kind"] = case.kind
    row["seconds"] = round(time.monotonic() - t0, 2)
    raw = os.path.join("raw", case.name + ".tsv")
    if os.path.exists(os.path.join(ctx.outdir, raw)):
        row["raw"] = raw
    return "ok", row


def select(cases, pattern):
    if not pattern:
        return cases
    rx = re.compile(pattern)
    return [c for c in cases if rx.search(c.name)]
