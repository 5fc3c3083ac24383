# SPDX-License-Identifier: Apache-2.0
"""Reading valgrind's callgrind output files: the total instruction count (Ir) of a
profile and the inclusive instructions per call of chosen functions, for the cost rows
of scripts/bench (ccommd and the application side under `valgrind --tool=callgrind`)."""

from .procs import Failed


def total_ir(path):
    """Total Ir of a callgrind output file (its 'summary:' or 'totals:' line)."""
    total = None
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("summary:") or line.startswith("totals:"):
                total = int(line.split()[1])
    if total is None:
        raise Failed("no totals in %s" % path)
    return total


def inclusive_calls(path):
    """{function: [calls, inclusive Ir of those calls]} summed over every call site,
    parsed from a callgrind output file (its cfn=/calls= records)."""
    names = {}
    out = {}

    def name_of(spec):
        spec = spec.strip()
        if spec.startswith("("):
            ident, _, rest = spec.partition(")")
            ident = ident + ")"
            rest = rest.strip()
            if rest:
                names[ident] = rest
            return names.get(ident, ident)
        return spec

    callee = None
    pending = None  # calls count of the next cost line
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("fn="):
                name_of(line[3:])
                callee = None
            elif line.startswith("cfn="):
                callee = name_of(line[4:])
            elif line.startswith("calls="):
                pending = int(line[6:].split()[0])
            elif pending is not None:
                parts = line.split()
                if len(parts) >= 2 and callee is not None:
                    try:
                        ir = int(parts[1])
                    except ValueError:
                        ir = 0
                    e = out.setdefault(callee, [0, 0])
                    e[0] += pending
                    e[1] += ir
                pending = None
    return out


def per_call(calls, wanted):
    """[(label, calls, Ir per call)] for the first function matching each wanted
    (label, substring)."""
    rows = []
    for label, sub in wanted:
        hits = [(fn, v) for fn, v in calls.items() if sub in fn]
        if not hits:
            continue
        n = sum(v[0] for _, v in hits)
        ir = sum(v[1] for _, v in hits)
        rows.append((label, n, round(ir / n, 1) if n else None))
    return rows
