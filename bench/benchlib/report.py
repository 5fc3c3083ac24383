# SPDX-License-Identifier: Apache-2.0
"""docs/performance.md from one scripts/bench run: every number in it comes from the
run's rows and meta; the prose only says how to read them. render() writes the document;
the target judgements are in targets.py, section 4 (cost) in cost.py, the closing
"Reproduce" sections in reproduce.py and the helpers they share in formatting.py."""

import os

from . import cost, peers, per_entry, reproduce
from .formatting import Rows, fmt_ratio, md_table, median, num, paired_ratios, ratio, style, us, usr
from .targets import TARGETS, checks, explain_misses


# The thesis' measured min/max one-way latency in µs (section 6.3): rate, min, max.
THESIS = {
    "6.2": [(100, 900, 2000), (200, 980, 2100), (300, 280, 2140), (400, 580, 1800), (500, 840, 2120),
            (600, 620, 1880), (800, 840, 2020), (1000, 400, 1450)],
    "6.3": [(100, 600, 2000), (200, 900, 3180), (300, 960, 2190), (400, 1120, 2600), (500, 1260, 2660),
            (600, 900, 2400), (800, 920, 3360)],
    "6.4": [(100, 1400, 1700), (200, 550, 2900), (300, 1100, 2250), (400, 1000, 2900), (500, 920, 2100),
            (600, 1100, 2280), (800, 950, 5000)],
}


def _what(r):
    """Plain words for a row."""
    n = r["name"]
    k = r.get("payload_bytes", 0) // 8
    if n.startswith("shm_spin"):
        return "floor: one cache line handed over, busy-read (RTT/2)"
    if n.startswith("shm_futex"):
        return "floor: futex wake-up (RTT/2)"
    if n.startswith("shm_eventfd"):
        return "floor: eventfd wake-up (RTT/2)"
    if n.startswith("iox_spin"):
        return "iceoryx, busy-poll (RTT/2)"
    if n.startswith("iox_waitset"):
        return "iceoryx, WaitSet (RTT/2)"
    if n.startswith("net_raw_oneway"):
        return "floor: raw AF_PACKET, plain sockets, one-way"
    if n.startswith("net_udp_oneway"):
        return "floor: UDP, plain sockets, one-way"
    if n.startswith("net_raw_rtt"):
        return "floor: raw AF_PACKET ping-pong (RTT/2)"
    if n.startswith("net_udp_rtt"):
        return "floor: UDP ping-pong (RTT/2)"
    if n.startswith("lcm"):
        return "LCM (UDP multicast) ping-pong (RTT/2)"
    if n.startswith("ccomm_pp_"):
        return "ccomm %s signal (%d B), process -> process ping-pong, %s (RTT/2)" % (
            r.get("signal_kind", "?"), r.get("payload_bytes", 0),
            "one clock reading per loop (`ccomm_set_time`)" if r.get("clock") == "cycle" else
            "clock read in every call")
    if n.startswith("ccomm_shm_event"):
        return "ccomm event signal, app -> app (one-way)"
    if n.startswith("ccomm_shm_state"):
        return "ccomm %d state double%s, app -> app (one-way)" % (k, "s" if k > 1 else "")
    if n.startswith("ccomm_") and "rtt_half" in n:
        return "ccomm %s, %d double%s, ping/echo through both daemons (RTT/2)" % (
            r["transport"], k, "s" if k > 1 else "")
    if n.startswith("ccomm_") and (r.get("elements") or 1) > 1:
        return "ccomm %s, one %d-element double array (one signal), app -> ccommd -> wire -> ccommd -> app" % (
            r["transport"], r["elements"])
    if n.startswith("ccomm_"):
        return "ccomm %s, %d double%s (separate signals), app -> ccommd -> wire -> ccommd -> app" % (
            r["transport"], k, "s" if k > 1 else "")
    return n


def _latency_table(rows, ref=None, ref_label="p50 / floor"):
    """Rows with p50 first (the headline), then the tails (flagged)."""
    rows = [dict(r, **{k: None for k in ("min_ns", "p50_ns", "p90_ns", "p99_ns", "p999_ns", "max_ns")})
            if not r["count"] else r for r in rows]
    head = ["case", "what", "receive", "bytes", "rate", "p50 µs", ref_label, "min", "p90", "p99 †", "p99.9 †",
            "max †", "n", "lost"]
    lines = []
    for r in rows:
        rf = ref(r) if ref else None
        lines.append(["`%s`" % r["name"], _what(r), style(r), r["payload_bytes"],
                      "b2b" if not r["rate_hz"] else "%g Hz" % r["rate_hz"], "**%s**" % us(r["p50_ns"]),
                      fmt_ratio(ratio(r, rf)) if rf else "", us(r["min_ns"]), us(r["p90_ns"]),
                      us(r["p99_ns"]), us(r["p999_ns"]), us(r["max_ns"]), r["count"], r["lost"]])
    return md_table(head, lines, ["l", "l", "l"] + ["r"] * 11)


def _thesis_ref(table, rate):
    for r, lo, hi in THESIS.get(table, []):
        if r == rate:
            return lo, hi
    return None


def _thesis_tables(R):
    out = []
    for exp, dirs in (("single", (("a2b", "6.2", "client -> server, 1 double"),)),
                      ("setup", (("a2b", "6.3", "control (A) -> planner (B), 36 doubles"),
                                 ("b2a", "6.4", "planner (B) -> control (A), 9 doubles")))):
        for direction, table, label in dirs:
            for mode in ("event", "periodic"):
                rows = [r for r in R.where(section="thesis", exp=exp, mode=mode)
                        if r.get("direction", "a2b") == direction and style(r) == "block"]
                if not rows:
                    continue
                rows.sort(key=lambda r: r["rate_hz"])
                out.append("#### %s, %s — %s (thesis table %s)\n" % (
                    "Single signal" if exp == "single" else "Setup-simulation", label,
                    "event-driven" if mode == "event" else "periodic (rate_hz = send rate)", table))
                lines = []
                for r in rows:
                    ref = _thesis_ref(table, int(r["rate_hz"]))
                    w = r.get("wire") or {}
                    lines.append(["%g" % r["rate_hz"], r["count"], usr(r, "min_ns"), "**%s**" % usr(r, "p50_ns"),
                                  usr(r, "p99_ns"), usr(r, "p999_ns"), usr(r, "max_ns"), r["lost"],
                                  "%d / %d" % (w.get("frames_lost", 0), r.get("wire_signals_lost", 0)),
                                  num(r.get("frames_per_cycle") if mode == "event" else r.get("packets_per_cycle")),
                                  num(r.get("tx_wakeups_per_cycle")),
                                  "%d" % ref[0] if ref else "-", "%d" % ref[1] if ref else "-"])
                out.append(md_table(["Hz", "n", "min µs", "p50 µs", "p99 † µs", "p99.9 † µs", "max † µs",
                                   "app missed", "wire lost (frames / values)", "frames / cycle",
                                   "send wake-ups / cycle", "thesis min µs", "thesis max µs"], lines))
                out.append("")
    return "\n".join(out)


def _spin_table(R):
    spin = [r for r in R.where(section="thesis") if style(r) == "spin"]
    if not spin:
        return ""
    lines = []
    for r in sorted(spin, key=lambda r: r["name"]):
        blk = next((b for b in R.where(section="thesis", exp=r.get("exp"), mode="event")
                    if b["rate_hz"] == r["rate_hz"] and style(b) == "block" and
                    b.get("direction") == r.get("direction")), None)
        for x in (blk, r):
            if x:
                lines.append(["`%s`" % x["name"], style(x), x["count"], usr(x, "min_ns"),
                              "**%s**" % usr(x, "p50_ns"), usr(x, "p99_ns"), usr(x, "max_ns"),
                              "%d of %s" % (x["lost"], x.get("sent"))])
    return ("#### 10 kHz: blocking against busy-polling receivers\n\nThe same event-driven 10 kHz runs with "
            "the receiving applications busy-polling (kept under a second: a spinning SCHED_FIFO thread is "
            "throttled after 0.95 s of each second). A cycle is 100 µs; a value the application has not read "
            "before the next one arrives is overwritten (state signals keep the last value) and counts as "
            "missed.\n\n" + md_table(["case", "receive", "n", "min µs", "p50 µs", "p99 † µs", "max † µs",
                                     "app missed"], lines) + "\n")


def _write_per_signal_section(R, meta, sections):
    """Section 8 (per-signal cost) into its own file, when this run measured any of it."""
    ratio_rows = []
    for t in ("raw", "udp"):
        f = R.get("net_%s_oneway_1khz_p288" % t)
        for name, label, key in (("ccomm_%s_oneway_block_1khz_p288" % t, "%s, 36 double signals" % t,
                                  "b2b_36_signals_ratio"),
                                 ("ccomm_%s_oneway_block_1khz_p288arr" % t, "%s, one 36-element array" % t,
                                  "b2b_array_ratio")):
            c = R.get(name)
            pairs = paired_ratios(c, f)
            x = median(pairs) if pairs else ratio(c, f)
            ratio_rows.append(("`%s` (%s)" % (name, label), c, f, pairs, x, TARGETS[key]))
    text = per_entry.section(R, meta, us, ratio_rows)
    if text and not meta.get("smoke"):
        os.makedirs(sections, exist_ok=True)
        with open(os.path.join(sections, per_entry.SECTION_FILE), "w", encoding="utf-8") as f:
            f.write(text)


def _machine(meta):
    rows = [
        ["date (UTC)", meta.get("date", "")],
        ["command", "`%s`" % meta.get("command", "scripts/bench")],
        ["ccomm commit", "%s%s" % (meta.get("git_commit", "?"), " (modified tree)" if meta.get("git_dirty") else "")],
        ["duration", "%s s" % meta.get("seconds", "?")],
        ["CPU", "%s, %s CPUs online, %s used (board A, board B)" % (
            meta.get("cpu_model", "?"), meta.get("cpus_online", "?"), meta.get("cpus_used"))],
        ["virtualization", meta.get("virtualization", "?")],
        ["memory", "%s GiB" % meta.get("mem_gib", "?")],
        ["OS / kernel", "%s, Linux %s (%s), clocksource %s" % (meta.get("os", "?"), meta.get("kernel", "?"),
                                                               meta.get("preempt", "?"),
                                                               meta.get("clocksource", "?"))],
        ["scheduling", "SCHED_FIFO %s for every measured program, ccommd threads %s; RT throttling %s us/s" % (
            meta.get("prio"), meta.get("daemon_prio") or ((meta.get("prio") or 70) + 10 if meta.get("prio") else "default"),
            meta.get("rt_runtime_us", "?"))],
        ["load average (1/5/15 min)", "start %s, end %s" % (" ".join(meta.get("loadavg_start", [])),
                                                             " ".join(meta.get("loadavg_end", [])))],
        ["peers", ", ".join("%s %s" % kv for kv in sorted((meta.get("versions") or {}).items()))],
    ]
    return md_table(["", ""], rows, ["l", "l"])


def render(rows, meta, problems, doc_dir, pngs, outdir=None):
    R = Rows(rows)
    cks = checks(R, meta)
    smoke = meta.get("smoke")
    L = []
    L.append("<!-- SPDX-License-Identifier: Apache-2.0 -->")
    L.append("<!-- Generated by scripts/bench; do not edit: rerun it. -->")
    L.append("# ccomm performance\n")
    if smoke:
        L.append("**SMOKE RUN: tiny sample counts, numbers are not meaningful.**\n")
    L.append("Measured with `%s` on %s (commit %s). Every number below comes from that one run: "
             "ccomm and every floor and peer it is compared with ran back to back on the same machine "
             "under the same conditions.\n" % (meta.get("command", "scripts/bench"), meta.get("date", "?"),
                                               meta.get("git_commit", "?")))
    L.append("How to read it: **p50 and ratios are the headline.** Tails (p99, p99.9, max; marked †) "
             "are reported but flagged: this is a 2-CPU virtual machine on a shared host (load average "
             "at start %s; the hypervisor's other guests are not visible in it), so tails show the host's "
             "scheduling more than ccomm, and even p50s move by 10-30%% between runs: judge ratios "
             "measured side by side, not absolute numbers. \"block\" = the receiver sleeps until woken "
             "(`ccomm_wait`, futex, eventfd, `recv`, WaitSet); \"spin\" = it busy-polls. ccomm rows are "
             "compared only with floors of the same receive style. One-way rows use the same clock on "
             "both ends (one machine); RTT/2 rows are half a round trip.\n" % (
                 " ".join(meta.get("loadavg_start", []))))

    L.append("## Targets\n")
    L.append(md_table(["target", "result", "measured"], [[c["text"], "**%s**" % c["status"], c["detail"]]
                                                       for c in cks], ["l", "l", "l"]))
    L.append("")
    L += explain_misses(R, meta, cks)
    retried = [r for r in rows if r.get("retried")]
    if retried:
        L.append("### Measurements that needed a second try\n")
        L.append(md_table(["case", "first try"], [["`%s`" % r["name"], r["retried"]] for r in retried],
                        ["l", "l"]))
        L.append("")
    if problems:
        L.append("### Cases that did not run\n")
        L.append(md_table(["case", "status", "reason"], [[p["name"], p["status"], p["reason"]] for p in problems],
                        ["l", "l", "l"]))
        L.append("")

    L.append("## Machine and conditions\n")
    L.append(_machine(meta))
    L.append("")
    L.append("Placement: board A = CPU %s, board B = CPU %s. On-target, the sending thread runs on CPU A and "
             "the receiving one on CPU B. Board to board, each namespace's ccommd (both threads, `<realtime "
             "cpu=>`) and application run on that board's CPU; the two namespaces are joined by a veth pair "
             "(no wire: the floor rows show what the kernel path costs here).\n" % tuple(
                 (meta.get("cpus_used") or ["?", "?"])[:2]))

    sec = [r for r in rows if r.get("section") == "ontarget"]
    if sec:
        L.append("## 1. On-target: app -> app through shared memory\n")
        L.append("Two kinds of ccomm rows. `ccomm_pp_*`: `ccomm_pingpong`, two processes on the two CPUs "
                 "passing a value back and forth through ccomm signals back to back, measured exactly like the "
                 "floors (`shm_floor`: one cache line handed between two processes, busy-read or futex/eventfd "
                 "wake-ups) and iceoryx %s (Debian, `iox_pingpong`): RTT/2, same payloads, same CPUs. Every "
                 "read asks for the value's freshness and age. `_cycle` rows take the time once per loop "
                 "iteration (`ccomm_set_time`, how a control loop uses ccomm: one clock reading per cycle for "
                 "all its signals), `_call` rows let every read and write read the clock. The busy-read rows "
                 "interleave the floor: blocks of 1000 round trips through a bare cache line alternate with "
                 "blocks through ccomm between the same two processes, so their ratio column compares with "
                 "the floor measured milliseconds apart (this host moves its virtual CPUs, and a floor measured "
                 "a second earlier can be 2x faster or slower), and the target table judges the median over "
                 "block pairs. `ccomm_shm_*`: control-loop shaped, one process writing at 1 kHz (write + "
                 "`ccomm_flush`) and its other thread reading on the other CPU, one-way; their blocking rows "
                 "are compared with a futex wake-up at the same 1 kHz (`shm_futex_1khz_p8`: at a rate the "
                 "sleeping CPU must be woken from idle, which back-to-back ping-pong never measures).\n\n"
                 "Design note: a small state value (up to 16 bytes) is copied into the same cache line as the "
                 "cell's `latest` word, and writers decide who fills that copy on a line readers never touch; "
                 "a reader polling a signal therefore reads one line, which the writer takes once per write. "
                 "Larger values are read from the newest slot and then served from the reading handle's own "
                 "copy until `latest` moves.\n" % (meta.get("versions") or {}).get("iceoryx", ""))

        def onref(r):
            if r["name"].startswith("shm_"):
                return None
            if r.get("floor_p50_ns"):
                return {"p50_ns": r["floor_p50_ns"]}  # the floor interleaved with it
            if style(r) == "spin":
                p = 288 if r["payload_bytes"] >= 288 else 8
                return R.get("shm_spin_b2b_p%d" % p) or R.get("shm_spin_b2b_p8")
            return R.get("shm_futex_1khz_p8") if r["rate_hz"] else R.get("shm_futex_b2b_p8")
        sec.sort(key=lambda r: (style(r) != "spin", r["payload_bytes"], r["name"].startswith("ccomm"), r["name"]))
        L.append(_latency_table(sec, onref))
        L.append("")
    sec = [r for r in rows if r.get("section") == "b2b"]
    if sec:
        L.append("## 2. Board -> board: two namespaces joined by veth\n")
        L.append("app -> ccommd -> wire -> ccommd -> app at 1 kHz, against plain sockets (no daemon) between "
                 "the same namespaces and LCM %s. Ratio: p50 against the floor with the same transport, payload "
                 "and metric (one-way rows against `net_*_oneway`, RTT/2 rows against `net_*_rtt_half`). The one-way "
                 "blocking rows ran in four alternations, floor then ccomm, each of 1-2 s, and a closing floor half; "
                 "the rows pool the samples of all halves, and the target table judges the median of the four "
                 "ratios of each ccomm half to the mean of the floor halves just before and after it, so that "
                 "neither a host drifting during the run nor a burst of load during one alternation decides it.\n" %
                 (meta.get("versions") or {}).get("liblcm1", ""))

        def bref(r):
            if not r["name"].startswith("ccomm_"):
                return None
            t = r["transport"]
            if r.get("metric") == "rtt_half":
                return R.get("net_%s_rtt_half_1khz_p8" % t)
            return R.get("net_%s_oneway_1khz_p%d" % (t, r["payload_bytes"]))
        sec.sort(key=lambda r: (r.get("metric", ""), r["payload_bytes"], r["name"]))
        L.append(_latency_table(sec, bref, "p50 / floor"))
        L.append("")
        st = [r for r in sec if r.get("stages") and r["name"].startswith("ccomm_")]
        if st:
            L.append("Where the one-way time goes (`ccomm-latency --stages`: each sample split at the moment "
                     "the receiving ccommd took the frame from the socket; p50 of each part on its own, so the "
                     "parts need not add up exactly):\n")
            lines = []
            for r in st:
                f = R.get("net_%s_oneway_1khz_p%d" % (r["transport"], r["payload_bytes"]))
                g = r["stages"]
                lines.append(["`%s`" % r["name"], style(r), "**%s**" % us(r["p50_ns"]),
                              us(g["upstream_p50_ns"]), us(f["p50_ns"]) if f else "-",
                              fmt_ratio(g["upstream_p50_ns"] / float(f["p50_ns"])) if f and f["p50_ns"] else "-",
                              us(g["last_hop_p50_ns"]), us(g["upstream_p99_ns"]), us(g["last_hop_p99_ns"])])
            L.append(md_table(["case", "receive", "total p50 µs", "app write -> far ccommd has the frame, p50",
                             "floor one-way p50 (socket -> socket)", "ratio", "far ccommd -> app, p50",
                             "upstream p99 †", "last hop p99 †"], lines, ["l", "l"] + ["r"] * 7))
            L.append("")
        fr = [r for r in sec if r.get("frames_per_cycle") is not None]
        if fr:
            L.append("Frames per cycle (the sending ccommd's frames_tx minus heartbeats / cycles sent): " +
                     ", ".join("`%s` %s" % (r["name"], r["frames_per_cycle"]) for r in fr) + ".\n")

    L += peers.section(R, meta, problems)

    if any(r.get("section") == "thesis" for r in rows):
        L.append("## 3. The thesis experiments\n")
        L.append("The thesis' single-signal and setup-simulation experiments (section 6.2; its results in tables "
                 "6.2-6.4 were read off an oscilloscope between two Overo boards at 100 Mbit with 1 kHz polling on "
                 "both sides). Here: raw Ethernet between the two namespaces, one-way from the producing "
                 "application's write to the consuming application seeing the whole cycle (blocking receive). "
                 "Setup-simulation: both applications send at the rate at the same time (36 doubles A->B, 9 "
                 "B->A). Event-driven: ccommd sends when the application flushes; periodic: every signal has "
                 "`rate_hz` = the send rate. \"app missed\": cycles the receiving application never saw "
                 "complete; \"wire lost\": frames missing in ccommd's sequence numbers / values ccommd counted "
                 "as lost. \"frames / cycle\": event-driven, the sending ccommd's frames_tx minus heartbeats "
                 "over the cycles sent (whole run); periodic, packets on eth0 per cycle in the steady part of the "
                 "run. \"send wake-ups / cycle\": ccommd's send thread wake-ups (`tx_wakeups`) per cycle. The "
                 "thesis' figures were measured on different hardware over a real switch: compare shape (how "
                 "latency grows with the rate), not absolute values.\n\n"
                 "Reading the rows: in periodic mode a value waits for ccommd's next period tick. The application "
                 "and ccommd run at the same rate from unsynchronised starts, so within a run the phase between "
                 "them, and with it the latency, is nearly constant (p50 close to p99), and between runs it is "
                 "anywhere from the event-driven latency up to one period: the thesis' polling design had the "
                 "same property, twice (its server polled too). When the write and the tick fall close "
                 "together, jitter moves some writes across the tick: one period then carries two cycles (the "
                 "older value is replaced and counts as \"app missed\") and the next none. Event-driven rows "
                 "have no such wait; their p50 "
                 "falls as the rate rises because at low rates the CPUs idle between cycles and each wake-up "
                 "starts from an idle (on this virtual machine: halted) CPU (compare `shm_futex_b2b_p8` with "
                 "`shm_futex_1khz_p8` in section 1 for the same effect on a bare futex).\n")
        L.append(_thesis_tables(R))
        L.append(_spin_table(R))
        fs = []
        for name, label in (("thesis_single_event_1khz", "single signal"),
                            ("thesis_setup_event_1khz_a2b", "setup A->B (36 doubles)"),
                            ("thesis_setup_event_1khz_b2a", "setup B->A (9 doubles)")):
            r = R.get(name)
            if r and r.get("bytes_per_frame"):
                b = r["bytes_per_frame"]
                fs.append("%s %.0f B (%.1f µs at 100 Mbit)" % (label, b, (max(b, 60) + 24) * 8 / 100.0))
        if fs:
            L.append("Frame sizes on eth0 (Ethernet header included), with the time such a frame takes on a "
                     "100 Mbit wire like the thesis' boards (plus preamble, FCS and gap): " + ", ".join(fs) +
                     ". Each value travels as a self-describing entry (signal id, type, count, value sequence "
                     "number, source time; docs/protocol.md), so a double costs 32 B on the wire (24 B entry header + "
                     "8 B value); "
                     "on 100 Mbit the setup-simulation frame alone takes as long as the whole path measured "
                     "here.\n")

    L.append("## 4. Cost\n")
    L.append(cost.tables(R, meta) or "(not measured in this run)\n")

    # Sections measured by other suites (system calls, ROS 2 bridge, recorder): each keeps
    # its own file, docs/perf/sections/*.md, and is copied here as it is.
    sections = os.path.join(doc_dir, "perf", "sections")
    _write_per_signal_section(R, meta, sections)
    def section_order(name):  # "10-x.md" after "9-y.md"
        number = name.split("-", 1)[0]
        return (int(number) if number.isdigit() else 1 << 30, name)

    for name in sorted(os.listdir(sections), key=section_order) if os.path.isdir(sections) else []:
        if name.endswith(".md"):
            text = open(os.path.join(sections, name), encoding="utf-8").read()
            L.append("".join(l for l in text.splitlines(True) if not l.startswith("<!--")).rstrip() + "\n")

    L.append("## Plots\n")
    for p in pngs:
        rel = os.path.relpath(p, doc_dir)
        L.append("![%s](%s)\n" % (os.path.basename(p), rel))

    L.append("## Reproduce\n")
    L.append("```\nscripts/bench            # this report: docs/performance.md, docs/perf/*.png (data in out/bench/)\n"
             "scripts/bench --smoke    # every case for a moment, into out/bench-smoke/ (CI)\n"
             "scripts/bench --list     # the plan\n```\n")
    L.append("Needs root (network namespaces, raw sockets, SCHED_FIFO) and the Debian packages listed in "
             "`scripts/bench --help` (LCM, iceoryx, valgrind, matplotlib); anything missing is "
             "reported as skipped. Raw samples, the generated configurations, every program's command line "
             "and log, and the callgrind profiles are in the data directory. Commands as run (from the "
             "repository root):\n")
    L.append(reproduce.commands(R, outdir) + "\n")
    L.append("## Running the benchmark on two real boards\n")
    L.append(reproduce.BOARDS)
    return "\n".join(L) + "\n", cks
