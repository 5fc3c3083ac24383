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
        series = []
        for r in grows:
            raw = r.get("raw")
            if not raw or not os.path.exists(os.path.join(outdir, raw)):
                continue
            v = sorted(ns for _, ns in results.load_raw(os.path.join(outdir, raw)) if ns >= 0)
            if v:
                series.append((r, v))
        if not series:
            continue
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(15, 6))
        cmap = plt.get_cmap("tab20")
        for k, (r, v) in enumerate(series):
            n = len(v)
            x = [ns / 1000.0 for ns in v]
            y = [(i + 1) / n for i in range(n)]
            # 20 distinct colours, then the same with dashes: no two rows look alike.
            style = {"color": cmap(k % 20), "linestyle": "-" if k < 20 else "--", "linewidth": 1}
            ax1.plot(x, y, label=_label(r), **style)
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
        fig.suptitle("latency distribution: %s" % group)
        fig.tight_layout()
        path = os.path.join(outdir, "%s_latency.png" % group)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

    if rows:
        fig, ax = plt.subplots(figsize=(11, 0.32 * len(rows) + 1.5))
        names = [_label(r) for r in rows]
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
        path = os.path.join(outdir, "summary.png")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written


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

