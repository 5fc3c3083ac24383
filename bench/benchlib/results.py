# SPDX-License-Identifier: Apache-2.0
"""Result rows: the schema every measurement (floor, peer, ccomm) reports in.

A row is a dict with at least SCHEMA_FIELDS. Programs in bench/ print one such
JSON object per line; ccomm rows can be made from raw samples with row_from_samples().
Optional keys used here: "metric" ("rtt", "rtt_half", "one_way"), "group" (which plot
a row belongs to), "raw" (raw-sample file relative to the output directory), "note".
"""

import json
import math
import os
import shutil

SCHEMA_FIELDS = (
    "name", "transport", "payload_bytes", "rate_hz",
    "min_ns", "p50_ns", "p90_ns", "p99_ns", "p999_ns", "max_ns", "mean_ns",
    "count", "lost",
)
_STR_FIELDS = ("name", "transport")
METRICS = ("rtt", "rtt_half", "one_way")


class SchemaError(ValueError):
    pass


def validate(row):
    """Raise SchemaError unless `row` carries every schema field with a sane value."""
    if not isinstance(row, dict):
        raise SchemaError("row is not an object")
    missing = [f for f in SCHEMA_FIELDS if f not in row]
    if missing:
        raise SchemaError("row %r lacks %s" % (row.get("name"), ", ".join(missing)))
    for f in SCHEMA_FIELDS:
        v = row[f]
        if f in _STR_FIELDS:
            if not isinstance(v, str) or not v:
                raise SchemaError("%s must be a non-empty string" % f)
        elif isinstance(v, bool) or not isinstance(v, (int, float)) or (isinstance(v, float) and math.isnan(v)):
            raise SchemaError("%s of %r must be a number, got %r" % (f, row["name"], v))
        elif v < 0:
            raise SchemaError("%s of %r is negative" % (f, row["name"]))
    if row["count"] > 0 and not (row["min_ns"] <= row["p50_ns"] <= row["p90_ns"] <= row["p99_ns"]
                                 <= row["p999_ns"] <= row["max_ns"]):
        raise SchemaError("percentiles of %r are not ordered" % row["name"])
    if "metric" in row and row["metric"] not in METRICS:
        raise SchemaError("unknown metric %r" % row["metric"])
    return row


def parse_program_output(stdout):
    """The result row from a bench program's stdout (its last JSON object line)."""
    for line in reversed(stdout.splitlines()):
        line = line.strip()
        if line.startswith("{"):
            return validate(json.loads(line))
    raise SchemaError("no JSON result line in output")


def percentile(sorted_values, q):
    """Nearest-rank percentile, the same definition as bench_pct() in bench_common.h."""
    n = len(sorted_values)
    if n == 0:
        return 0
    k = math.ceil(q * n)
    return sorted_values[min(max(k, 1), n) - 1]


def row_from_samples(name, transport, payload_bytes, rate_hz, samples_ns, lost, **extra):
    """Build a schema row from raw latency samples (ns); for ccomm rows and checks."""
    v = sorted(int(x) for x in samples_ns)
    row = {
        "name": name, "transport": transport, "payload_bytes": payload_bytes, "rate_hz": rate_hz,
        "min_ns": v[0] if v else 0,
        "p50_ns": percentile(v, 0.50), "p90_ns": percentile(v, 0.90),
        "p99_ns": percentile(v, 0.99), "p999_ns": percentile(v, 0.999),
        "max_ns": v[-1] if v else 0,
        "mean_ns": (sum(v) / len(v)) if v else 0.0,
        "count": len(v), "lost": int(lost),
    }
    row.update(extra)
    return validate(row)


def load_raw(path):
    """Raw samples written with --dump: [(seq, ns)], ns == -1 for a lost message."""
    out = []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if len(parts) == 2:
                out.append((int(parts[0]), int(parts[1])))
    return out


def write_results(outdir, rows, meta=None, skipped=None):
    """results.json: {"meta": ..., "results": [rows], "skipped": [...]}; returns its path."""
    os.makedirs(outdir, exist_ok=True)
    for r in rows:
        validate(r)
    doc = {"schema": list(SCHEMA_FIELDS), "meta": meta or {}, "results": rows, "skipped": skipped or []}
    path = os.path.join(outdir, "results.json")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=1, sort_keys=False)
        f.write("\n")
    os.replace(tmp, path)
    return path


def load_results(path_or_dir):
    path = path_or_dir
    if os.path.isdir(path):
        path = os.path.join(path, "results.json")
    with open(path) as f:
        doc = json.load(f)
    for r in doc.get("results", []):
        validate(r)
    return doc


def _us(ns):
    return "%.2f" % (ns / 1000.0) if ns < 100_000 else "%.0f" % (ns / 1000.0)


def format_table(rows):
    """Fixed-width table, latencies in microseconds."""
    head = ("name", "transport", "metric", "bytes", "rate", "p50 us", "p90 us", "p99 us", "p99.9 us",
            "max us", "mean us", "count", "lost")
    lines = [head]
    for r in rows:
        rate = "b2b" if not r["rate_hz"] else ("%g" % r["rate_hz"])
        lines.append((
            r["name"], r["transport"], r.get("metric", "?"), str(r["payload_bytes"]), rate,
            _us(r["p50_ns"]), _us(r["p90_ns"]), _us(r["p99_ns"]), _us(r["p999_ns"]),
            _us(r["max_ns"]), _us(r["mean_ns"]), str(r["count"]), str(r["lost"]),
        ))
    widths = [max(len(l[i]) for l in lines) for i in range(len(head))]
    out = []
    for j, l in enumerate(lines):
        cells = [c.ljust(widths[i]) if i < 3 else c.rjust(widths[i]) for i, c in enumerate(l)]
        out.append("  ".join(cells).rstrip())
        if j == 0:
            out.append("  ".join("-" * w for w in widths))
    return "\n".join(out)


def load_rows(path):
    """Rows from a results.json (or its directory), or from a file of JSON lines as the
    programs print them. Each row's "raw" is made absolute so it can be copied."""
    if os.path.isdir(path) or path.endswith("results.json"):
        doc = load_results(path)
        base = path if os.path.isdir(path) else os.path.dirname(path)
        rows = doc.get("results", [])
    else:
        base = os.path.dirname(path)
        rows = []
        with open(path) as f:
            for line in f:
                line = line.strip()
                if line.startswith("{"):
                    rows.append(validate(json.loads(line)))
    for r in rows:
        if r.get("raw") and not os.path.isabs(r["raw"]):
            r["raw"] = os.path.join(os.path.abspath(base), r["raw"])
    return rows


def adopt_rows(rows, outdir):
    """Make rows from elsewhere part of outdir: raw files copied under outdir/raw/."""
    os.makedirs(os.path.join(outdir, "raw"), exist_ok=True)
    for r in rows:
        src = r.get("raw")
        if src and os.path.isabs(src):
            rel = os.path.join("raw", r["name"] + ".tsv")
            dst = os.path.join(outdir, rel)
            if os.path.exists(src):
                if os.path.abspath(src) != os.path.abspath(dst):
                    shutil.copyfile(src, dst)
                r["raw"] = rel
            else:
                del r["raw"]
    return rows
