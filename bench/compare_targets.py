#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Side by side: the target tables of two scripts/bench reports (docs/performance.md as
committed, and a new run's report), row by row, with each row's headline ratio.

    python3 bench/compare_targets.py BEFORE.md AFTER.md [--title T] > OUT.md

The headline of a row is the bold median ratio when the row has one (interleaved or
alternated measurements), else its last "N.NNx". Rows are matched by target text and
position among rows with the same text.
"""
import argparse
import re
import sys


def targets(path):
    rows, seen, meta = [], {}, ""
    for line in open(path, encoding="utf-8"):
        if line.startswith("Measured with `scripts/bench"):
            m = re.search(r"on (\S+) \(commit (\w+)\)", line)
            meta = "run of %s at commit %s" % m.groups() if m else line.strip()
        m = re.match(r"\| (.+?) \| \*\*(met|MISSED|reported|skipped)\*\* \| (.*) \|\s*$", line)
        if not m or m.group(1) == "target":
            continue
        name, result, measured = m.groups()
        k = seen.get(name, 0)
        seen[name] = k + 1
        bold = re.findall(r"median \*\*([0-9.]+x)\*\*", measured)
        ratios = re.findall(r"([0-9]+\.[0-9]+x)", measured)
        head = bold[-1] if bold else (ratios[-1] if ratios else "")
        rows.append(((name, k), result, head))
    return rows, meta


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--title", default="Targets before and after")
    a = ap.parse_args()
    before, meta_b = targets(a.before)
    after, meta_a = targets(a.after)
    new = {key: (res, head) for key, res, head in after}
    print("## %s\n" % a.title)
    print("- before: %s\n- after: %s\n" % (meta_b or a.before, meta_a or a.after))
    print("| target | before | after |")
    print("|:---|:---|:---|")
    for key, res, head in before:
        res2, head2 = new.get(key, ("not run", ""))
        print("| %s | %s %s | %s %s |" % (key[0], res, head, res2, head2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
