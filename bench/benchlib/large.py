# SPDX-License-Identifier: Apache-2.0
"""Large values (docs/protocol.md "Large values"): one double array of 1 KiB (one frame)
and one of 64 KiB (47 fragments) sent board -> board at 100 Hz, one-way latency from the
producer's write to the reader, and the CPU time both ccommd spent per value. The rows go
to results.json (section "large"); docs/perf/sections/11-large-values.md reports them."""

import os

from . import ccomm
from .ccomm import Daemons

SIGNAL = "big"


def pair_config(names, count, transport, ns_pair, prio, cpus):
    """The bench's two boards with one double[count] signal names[0] -> names[1]."""
    return ccomm.pair_config(names, ["%s:%d" % (SIGNAL, count)], [], transport, ns_pair, 0, prio, cpus)


def run_large(ctx, case):
    ctx.need("ccommd", "ccomm", "ccomm-latency")
    o = case.opts
    names = ("client", "server")
    cfg = pair_config(names, o["count"], o["transport"], ctx.netns(), ctx.daemon_prio,
                      ctx.cpus if ctx.cpus else None)
    nodes = [(names[0], "a", ctx.cpu("a")), (names[1], "b", ctx.cpu("b"))]
    rate, warm = o["rate"], 0.5
    dur = case.seconds + warm
    with Daemons(ctx.bins, cfg, nodes, ctx.workdir, case.name, ns_pair=ctx.netns(), no_rt=ctx.no_rt) as d:
        samples = os.path.join(ctx.workdir, case.name + ".b.samples")

        def app(side, node, duration, label, path, mode="oneway"):
            argv = ccomm.latency_argv(ctx.bins, node, rate, duration, ctx.prio, label, path, mode=mode,
                                      send=[SIGNAL] if side == "a" else None,
                                      recv=[SIGNAL] if side == "b" else None, warmup=warm, stages=True)
            cpu = ctx.cpu(side)
            return d.wrap(side, ccomm.placed(argv, ctx.prio, [cpu] if cpu is not None else None))

        before = d.stats_all(list(names))
        cpu0 = {n: d.cpu(n) for n in names}
        res = ccomm.run_apps(d, [("b", app("b", names[1], dur + 0.6, case.name, samples), 0.0),
                                 ("a", app("a", names[0], dur, case.name + "-src",
                                           os.path.join(ctx.workdir, case.name + ".a.samples")), 0.3)], dur + 30)
        cpu1 = {n: d.cpu(n) for n in names}
        after = d.stats_all(list(names))
    sent = res["a"]["sent"]
    # CPU time (all threads) of each ccommd over the run, per value sent. It includes the
    # daemons' background (supervision tick, heartbeats), the same at both sizes, so
    # the difference between the 64 KiB and the 1 KiB row is what the fragments cost.
    per_value = {}
    for n, key in ((names[0], "cpu_tx_daemon_ns_per_value"), (names[1], "cpu_rx_daemon_ns_per_value")):
        if cpu0[n] and cpu1[n] and sent:
            per_value[key] = round((cpu1[n][1] - cpu0[n][1]) / float(sent))

    def delta(node, key, counter=False):
        if not (before.get(node) and after.get(node)):
            return None
        if counter:
            return after[node]["counters"].get(key, 0) - before[node]["counters"].get(key, 0)
        sig = lambda st: next(s for s in st["signals"] if s["name"] == SIGNAL)
        return sig(after[node]).get(key, 0) - sig(before[node]).get(key, 0)
    for k in ("rx", "lost", "values_incomplete", "fragments_refused"):
        per_value["daemon_" + k] = delta(names[1], k)
    per_value["daemon_tx_coalesced"] = delta(names[0], "coalesced")
    per_value["daemon_socket_drops"] = delta(names[1], "socket_drops", counter=True)
    payload = 8 * o["count"]
    row = ccomm.samples_row(case.name, o["transport"], payload, rate, res["b"], samples, ctx.rawdir,
                            style="block", signals=1, signal_kind="state", torn=res["b"].get("torn", 0), sent=sent,
                            command=res["b"]["argv"], daemon_command=d.argv[names[0]], **per_value)
    return [row]
