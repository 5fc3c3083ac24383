# SPDX-License-Identifier: Apache-2.0
"""Small helpers shared by the report modules (report.py, targets.py, cost.py): the Rows
lookup, a row's receive style, p50 ratios (pooled, and alternation by alternation), and
the text of latencies, numbers, ratios and markdown tables."""


class Rows:
    """A run's rows by name (get) and by field values (where)."""

    def __init__(self, rows):
        self.rows = rows
        self.by = {r["name"]: r for r in rows}

    def get(self, name):
        return self.by.get(name)

    def where(self, **kw):
        return [r for r in self.rows if all(r.get(k) == v for k, v in kw.items())]


def style(r):
    """A row's receive style: "block" (woken) or "spin" (busy-polls)."""
    if r.get("style"):
        return r["style"]
    n = r["name"]
    return "spin" if n.startswith(("shm_spin", "iox_spin")) else "block"


def ratio(a, b):
    """p50 of a over p50 of b (all samples pooled), or None."""
    if a is None or b is None or not b.get("p50_ns") or not a.get("p50_ns"):
        return None
    return a["p50_ns"] / float(b["p50_ns"])


def paired_ratios(a, b):
    """Ratios of the p50s of repeated halves, alternation by alternation, or [] when the
    rows were not measured in alternation. a's half k ran after b's half k (ratio to it);
    when b has one half more (a closing one), a's half k ran between b's halves k and k+1
    and is compared with their mean."""
    ra, rb = (a or {}).get("rep_p50_ns") or [], (b or {}).get("rep_p50_ns") or []
    if len(ra) < 2:
        return []
    if len(rb) == len(ra) + 1:
        if not all(rb):
            return []
        rb = [(x + y) / 2.0 for x, y in zip(rb, rb[1:])]
    if len(ra) != len(rb):
        return []
    return [x / float(y) for x, y in zip(ra, rb) if x and y]


def median(v):
    v = sorted(v)
    n = len(v)
    return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2.0


def us(ns):
    """Nanoseconds as microseconds, with fewer decimals the larger they are."""
    if ns is None:
        return "-"
    v = ns / 1000.0
    if v < 1:
        return "%.3f" % v  # sub-microsecond rows (shared memory): to the nanosecond
    if v < 10:
        return "%.2f" % v
    if v < 1000:
        return "%.1f" % v
    return "%.0f" % v


def usr(r, key):
    """A latency of a row, "-" when nothing was received."""
    return us(r[key]) if r.get("count") else "-"


def num(x):
    return "-" if x is None else "%.3g" % x


def fmt_ratio(x):
    return "-" if x is None else "%.2fx" % x


def md_table(head, lines, align=None):
    """A markdown table; align: "l" or "r" per column (default: first left, rest right)."""
    align = align or ["l"] + ["r"] * (len(head) - 1)
    out = ["| " + " | ".join(head) + " |",
           "|" + "|".join(":---" if a == "l" else "---:" for a in align) + "|"]
    for l in lines:
        out.append("| " + " | ".join(str(c) for c in l) + " |")
    return "\n".join(out)
