# SPDX-License-Identifier: Apache-2.0
"""Latency distribution plots (PNG) from a results directory.

    python3 -m benchlib.plot OUTDIR      (run from scripts/)

For each plot group ("shm", "net", and any group a later row brings, e.g. "ccomm"):
<group>_latency.png with the CDF and the tail (fraction of samples above x, log
scale, where p99.9 and the outliers show), from the raw sample files. summary.png:
p50 bar with p99 and max markers for every row, log scale. Needs matplotlib
(Debian: python3-matplotlib); plots() returns [] with a note when it is missing.
"""

import os
import sys

from . import results


def available():
    try:
        import matplotlib  # noqa: F401
        return True
    except ImportError:
        return False


def _label(r):
    rate = "b2b" if not r["rate_hz"] else "%g Hz" % r["rate_hz"]
    return "%s (%s, %s B, %s)" % (r["name"], r.get("metric", "?"), r["payload_bytes"], rate)


def plots(outdir, rows=None):
    """Write the PNGs into outdir; returns their paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if rows is None:
        rows = results.load_results(outdir)["results"]
    written = []
    groups = {}
    for r in rows:
        groups.setdefault(r.get("group", "other"), []).append(r)

    for group, grows in sorted(groups.items()):
        path = os.path.join(outdir, "%s_latency.png" % group)
        if _cdf_figure(plt, outdir, grows, "latency distribution: %s" % group, path):
            written.append(path)

    if rows:
        path = os.path.join(outdir, "summary.png")
        _summary_figure(plt, rows, path)
        written.append(path)
    return written


def _series(outdir, rows):
    out = []
    for r in rows:
        raw = r.get("raw")
        if not raw or not os.path.exists(os.path.join(outdir, raw)):
            continue
        v = sorted(ns for _, ns in results.load_raw(os.path.join(outdir, raw)) if ns >= 0)
        if v:
            out.append((r, v))
    return out


def _cdf_figure(plt, outdir, rows, title, path, label=None, style_of=None):
    """CDF and tail (P(latency > x), log) of the rows' raw samples; False if none.
    style_of(row, k): matplotlib line style, default: 20 colours then dashed."""
    series = _series(outdir, rows)
    if not series:
        return False
    label = label or _label
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(15, 6))
    cmap = plt.get_cmap("tab20")
    for k, (r, v) in enumerate(series):
        n = len(v)
        x = [ns / 1000.0 for ns in v]
        y = [(i + 1) / n for i in range(n)]
        # 20 distinct colours, then the same with dashes: no two rows look alike.
        style = style_of(r, k) if style_of else {"color": cmap(k % 20), "linestyle": "-" if k < 20 else "--",
                                                  "linewidth": 1}
        ax1.plot(x, y, label=label(r), **style)
        # Survival: P(latency > x); 1/n floor so the last point stays on a log axis.
        ax2.plot(x, [max(1.0 - yy, 1.0 / n) for yy in y], **style)
    for ax in (ax1, ax2):
        ax.set_xscale("log")
        ax.set_xlabel("latency [µs]")
        ax.grid(True, which="both", alpha=0.3)
    ax1.set_ylabel("fraction of samples ≤ x (CDF)")
    ax2.set_yscale("log")
    ax2.set_ylabel("fraction of samples > x (tail)")
    for q in (1e-2, 1e-3):
        ax2.axhline(q, color="grey", linestyle=":", linewidth=0.8)
    ax1.legend(fontsize=7, loc="lower right")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


def _summary_figure(plt, rows, path, label=None):
    label = label or _label
    fig, ax = plt.subplots(figsize=(11, 0.32 * len(rows) + 1.5))
    names = [label(r) for r in rows]
    ys = list(range(len(rows)))[::-1]
    p50 = [max(r["p50_ns"], 1) / 1000.0 for r in rows]
    ax.barh(ys, p50, color="tab:blue", alpha=0.7, label="p50")
    ax.scatter([max(r["p99_ns"], 1) / 1000.0 for r in rows], ys, marker="|", s=150, color="tab:red",
               label="p99", zorder=3)
    ax.scatter([max(r["max_ns"], 1) / 1000.0 for r in rows], ys, marker="x", s=25, color="black",
               label="max", zorder=3)
    ax.set_yticks(ys)
    ax.set_yticklabels(names, fontsize=7)
    ax.set_xscale("log")
    ax.set_xlabel("latency [µs] (metric per row: rtt, rtt_half = RTT/2, one_way)")
    ax.grid(True, axis="x", which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_xlim(left=min(p50) / 2 if p50 else 0.01)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _bench_label(r):
    style = r.get("style") or ("spin" if r["name"].startswith(("shm_spin", "iox_spin")) else "block")
    rate = "b2b" if not r["rate_hz"] else "%g Hz" % r["rate_hz"]
    return "%s (%s, %s, %s B, %s)" % (r["name"], r.get("metric", "?"), style, r["payload_bytes"], rate)


def _style_by_family(plt, rows):
    """ccomm solid, floors dashed, peers dotted; one colour per (transport or kind,
    payload, receive style), so a ccomm row and the floor it is read against match."""
    cmap = plt.get_cmap("tab10")
    keys = []

    def key(r):
        n = r["name"]
        fam = "iox" if n.startswith("iox") else ("lcm" if n.startswith("lcm") else r["transport"])
        if fam == "iceoryx":
            fam = "iox"
        style = r.get("style") or ("spin" if "_spin_" in n else "block")
        return (fam if not n.startswith(("iox", "lcm")) else "peer-" + fam, r["payload_bytes"], style)

    for r in rows:
        if key(r) not in keys:
            keys.append(key(r))

    def style_of(r, k):
        n = r["name"]
        ls = "-" if n.startswith("ccomm") else (":" if n.startswith(("iox", "lcm")) else "--")
        return {"color": cmap(keys.index(key(r)) % 10), "linestyle": ls,
                "linewidth": 1.6 if n.startswith("ccomm") else 1.1}
    return style_of


def bench_plots(outdir, rows, plots_dir, thesis_ref=None):
    """scripts/bench's figures, written into plots_dir: on-target and board-to-board
    latency distributions, the thesis sweep against the thesis' min/max, a p50 summary."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(plots_dir, exist_ok=True)
    written = []
    figures = [
        ("ontarget_latency.png", "on-target, app -> app through shared memory",
         lambda r: r.get("section") == "ontarget"),
        ("b2b_oneway_latency.png", "board -> board one-way, two namespaces joined by veth, 1 kHz",
         lambda r: r.get("section") == "b2b" and r.get("metric") == "one_way"),
        ("b2b_rtt_latency.png", "board -> board RTT/2 (ping-pong), ccomm, floors and LCM, 1 kHz",
         lambda r: r.get("section") == "b2b" and r.get("metric") != "one_way"),
    ]
    for fname, title, pick in figures:
        sel = [r for r in rows if pick(r)]
        path = os.path.join(plots_dir, fname)
        if _cdf_figure(plt, outdir, sel, "latency distribution: " + title, path, _bench_label,
                       _style_by_family(plt, sel)):
            written.append(path)

    th = [r for r in rows if r.get("section") == "thesis"]
    sel = [r for r in th if r["rate_hz"] in (1000, 10000)]
    path = os.path.join(plots_dir, "thesis_latency.png")
    if _cdf_figure(plt, outdir, sel, "thesis experiments at 1 kHz and 10 kHz (one-way, raw Ethernet)", path,
                   lambda r: "%s (%s B)" % (r["name"], r["payload_bytes"])):
        written.append(path)
    if th:
        path = os.path.join(plots_dir, "thesis_rates.png")
        _thesis_rates(plt, th, path, thesis_ref or {})
        written.append(path)

    rest = [r for r in rows if r.get("section") in ("ontarget", "b2b")]
    if rest:
        path = os.path.join(plots_dir, "summary.png")
        _summary_figure(plt, rest, path, _bench_label)
        written.append(path)
    return written


def _thesis_rates(plt, rows, path, ref):
    """p50/p99/max against the send rate per experiment and mode, with the thesis'
    measured min..max (tables 6.2-6.4) as grey bars."""
    fig, axes = plt.subplots(2, 2, figsize=(14, 9), sharex=True, sharey=True)
    for i, exp in enumerate(("single", "setup")):
        for j, mode in enumerate(("event", "periodic")):
            ax = axes[i][j]
            sel = [r for r in rows if r.get("exp") == exp and r.get("mode") == mode and r.get("style") != "spin"]
            spin = [r for r in rows if r.get("exp") == exp and r.get("mode") == mode and r.get("style") == "spin"]
            for r in spin:
                ax.plot([r["rate_hz"]], [max(r["p50_ns"], 1) / 1000.0], marker="*", markersize=10, color="tab:green",
                        linestyle="none", label="%s p50, busy-polling receiver" % {"a2b": "A->B", "b2a": "B->A"}.get(
                            r.get("direction", "a2b"), ""))
            for direction, marker in (("a2b", "o"), ("b2a", "s")):
                d = sorted((r for r in sel if r.get("direction", "a2b") == direction), key=lambda r: r["rate_hz"])
                if not d:
                    continue
                x = [r["rate_hz"] for r in d]
                lab = {"a2b": "A->B", "b2a": "B->A"}[direction] if exp == "setup" else "client->server"
                for key, colour in (("p50_ns", "tab:blue"), ("p99_ns", "tab:orange"), ("max_ns", "tab:red")):
                    ax.plot(x, [r[key] / 1000.0 for r in d], marker=marker, color=colour, markersize=4,
                            linestyle="-" if direction == "a2b" else "--",
                            label="%s %s" % (lab, key[:-3].replace("p999", "p99.9")))
            for table, (colour, off) in (("6.2", ("grey", 0.0)), ("6.3", ("grey", -0.02)),
                                          ("6.4", ("silver", 0.02))):
                pts = ref.get(table)
                if not pts or (exp == "single") != (table == "6.2"):
                    continue
                for rate, lo, hi in pts:
                    ax.plot([rate * (1 + off)] * 2, [lo, hi], color=colour, linewidth=5, alpha=0.6,
                            solid_capstyle="butt")
                ax.plot([], [], color=colour, linewidth=5, alpha=0.6, label="thesis table %s min..max" % table)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("send rate [Hz]")
            ax.set_ylabel("one-way latency [µs]")
            ax.set_title("%s, %s" % ("single signal" if exp == "single" else "setup-simulation (36 + 9 doubles)",
                                     "event-driven" if mode == "event" else "periodic"))
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=6, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv):
    if len(argv) != 2:
        print("usage: python3 -m benchlib.plot OUTDIR", file=sys.stderr)
        return 2
    if not available():
        print("matplotlib not available for %s (Debian: python3-matplotlib)" % sys.executable, file=sys.stderr)
        return 4
    for p in plots(argv[1]):
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

