# SPDX-License-Identifier: Apache-2.0
"""Section 4 of docs/performance.md, Cost: ccommd's CPU time per forwarded signal in the
thesis runs (stat and schedstat, idle subtracted), the idle daemons' CPU, and callgrind's
instructions per forwarded signal and per call (daemon and application side)."""

from .formatting import md_table, num, style


def _periodic_cost(R):
    """One sentence comparing periodic with event-driven CPU, from the 1 kHz setup rows."""
    ev = next((r for r in R.where(section="thesis", exp="setup", mode="event", direction="a2b")
               if r["rate_hz"] == 1000 and style(r) == "block" and r.get("cpu")), None)
    pe = next((r for r in R.where(section="thesis", exp="setup", mode="periodic", direction="a2b")
               if r["rate_hz"] == 1000 and r.get("cpu")), None)
    if not (ev and pe):
        return ""

    def ms(r):
        return sum(v["cpu_ms_sched"] for k, v in r["cpu"].items() if k != "wall_s") / r["cpu"]["wall_s"]
    return (" At 1 kHz the setup-simulation's daemons use %.2fx the CPU in periodic mode that they use "
            "event-driven, with %s vs %s packets and %s vs %s send-thread wake-ups per cycle (thesis tables)." % (
                ms(pe) / ms(ev), num(pe.get("packets_per_cycle")), num(ev.get("frames_per_cycle")),
                num(pe.get("tx_wakeups_per_cycle")), num(ev.get("tx_wakeups_per_cycle"))))


def tables(R, meta):
    """The section's text below its heading; "" when this run measured none of it."""
    cost = meta.get("cost") or {}
    out = []
    rows = [r for r in R.where(section="thesis") if r.get("cpu") and r.get("forwarded")]
    idle = cost.get("idle")
    # Idle CPU per second of both daemons together (schedstat), to subtract the fixed part.
    idle_ms_per_s = None
    if idle and idle.get("wall_s"):
        idle_ms_per_s = sum(v["cpu_ms_sched"] for k, v in idle.items() if k != "wall_s") / idle["wall_s"]
    seen = set()
    lines = []
    for r in sorted(rows, key=lambda r: (r["exp"], r["mode"], r["rate_hz"])):
        key = (r["exp"], r["mode"], r["rate_hz"], style(r))
        if key in seen or r["rate_hz"] not in (100, 1000, 10000) or style(r) != "block":
            continue
        seen.add(key)
        cpu = r["cpu"]
        nodes = [k for k in cpu if k != "wall_s"]
        ticks_ms = sum(cpu[n]["cpu_ms_ticks"] for n in nodes)
        sched_ms = sum(cpu[n]["cpu_ms_sched"] for n in nodes)
        user_ms = sum(cpu[n].get("user_ms", 0) for n in nodes)
        sys_ms = sum(cpu[n].get("system_ms", 0) for n in nodes)
        fw = r["forwarded"]
        lines.append(["%s / %s" % (r["exp"], r["mode"]), "%g" % r["rate_hz"], fw, "%.2f" % cpu["wall_s"],
                      "%.0f (%.0f + %.0f)" % (ticks_ms, user_ms, sys_ms), "%.1f" % sched_ms,
                      "**%.2f**" % (ticks_ms / fw * 1000) if fw else "-",
                      "%.2f" % (sched_ms / fw * 1000) if fw else "-",
                      "%.2f" % ((sched_ms - idle_ms_per_s * cpu["wall_s"]) / fw * 1000)
                      if fw and idle_ms_per_s is not None else "-",
                      "%.1f" % (100.0 * sched_ms / 1000.0 / cpu["wall_s"] / max(1, len(nodes)))])
    if lines:
        out.append("CPU time of both ccommd processes over a thesis run (board A and board B together), "
                   "per 1000 forwarded signals (a forwarded signal = one value sent by one daemon and "
                   "stored by the other; CPU = utime+stime from /proc/PID/stat, in %s Hz clock ticks, and "
                   "the scheduler's run time from /proc/PID/task/*/schedstat, in ns):\n" % meta.get("clk_tck", 100))
        out.append(md_table(["experiment / mode", "Hz", "forwarded", "wall s", "CPU ms, stat (user + system)",
                           "CPU ms (schedstat)",
                           "ms / 1000 signals (stat)", "ms / 1000 signals (schedstat)",
                           "ms / 1000 signals, idle subtracted", "% of a CPU per daemon"],
                          lines))
        out.append("")
        out.append("Reading it: most of ccommd's CPU time is system time (the `sendto`/`recvfrom` calls into the "
                   "veth path, futex wake-ups), and it is paid per frame, so batching many signals into one "
                   "frame (setup-simulation) costs far less per signal than one signal per frame; at low rates "
                   "the fixed part (heartbeats, the supervision tick, see idle below) dominates. The "
                   "\"idle subtracted\" column removes the idle CPU rate measured below.%s\n" % _periodic_cost(R))
    idle = cost.get("idle")
    if idle:
        nodes = [k for k in idle if k != "wall_s"]
        out.append("Idle (both setup-simulation daemons up, no application, heartbeats every 100 ms, "
                   "supervision every 100 ms when idle) for %.1f s:\n" % idle["wall_s"])
        out.append(md_table(["daemon", "CPU ms (stat)", "CPU ms (schedstat)", "µs CPU per s", "% of a CPU"],
                          [[n, "%.0f" % idle[n]["cpu_ms_ticks"], "%.2f" % idle[n]["cpu_ms_sched"],
                            "%.0f" % (idle[n]["cpu_ms_sched"] * 1000 / idle["wall_s"]),
                            "%.3f" % (idle[n]["cpu_ms_sched"] / 10.0 / idle["wall_s"])] for n in nodes]))
        out.append("")
        out.append("Before and after issue 38's cuts of the idle (supervision on its own schedule instead of "
                   "every 10 ms, commit 148236e; the receive thread's socket wait 1 s instead of 100 ms, ab82469), "
                   "measured on 2026-12-04 on this machine in one session, quiet (load 0.12), `scripts/bench --only "
                   "'^cost_idle$' --scale 5` (15 s), the two builds alternating twice: before (d9e0fe6) 0.531 / "
                   "0.665 % and 0.505 / 0.511 % of a CPU per daemon, after 0.230 / 0.251 % and 0.252 / 0.252 %; "
                   "`strace -f -c` of one idle ccommd for 6 s: rt_sigtimedwait 587 -> 155, recvfrom 168 -> 67.\n")
    cg = cost.get("callgrind") or {}
    if cg:
        out.append("Instructions per forwarded signal (`valgrind --tool=callgrind`, user space only: system "
                   "calls and the kernel's network stack are not counted). Each daemon ran twice for the same "
                   "time under callgrind, once with the applications sending at the given rate and once idle; "
                   "(Ir traffic - Ir idle) / (signals the daemon sent + received):\n")
        lines = []
        for exp, res in sorted(cg.items()):
            for n, v in res["nodes"].items():
                lines.append([exp, "%g" % res["rate"], n, v["tx"], v["rx"], "{:,}".format(v["ir_traffic"]),
                              "{:,}".format(v["ir_idle"]), "**%s**" % v["ir_per_signal"]])
        out.append(md_table(["experiment", "Hz", "daemon", "signals sent", "signals received", "Ir traffic", "Ir idle",
                           "Ir / forwarded signal"], lines))
        out.append("")
        for exp, res in sorted(cg.items()):
            for n, v in res["nodes"].items():
                if not v.get("per_call"):
                    continue
                out.append("ccommd %s (%s): inclusive instructions per call of the functions on the "
                           "forwarding path:\n" % (n, exp))
                out.append(md_table(["what", "calls", "Ir / call"], [[w, c, x] for w, c, x in v["per_call"]],
                                  ["l", "r", "r"]))
                out.append("")
    cl = cost.get("callgrind_client")
    if cl:
        out.append("The application side (libccomm in `ccomm-latency` under callgrind, %d state doubles written "
                   "and read per cycle at %g Hz, blocking receive): inclusive instructions per call:\n" % (
                       cl["signals"], cl["rate"]))
        out.append(md_table(["call", "calls", "Ir / call"], [[w, c, x] for w, c, x in cl["per_call"]],
                          ["l", "r", "r"]))
        out.append("")
    return "\n".join(out)
