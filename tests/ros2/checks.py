#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Checks of the ROS 2 bridge tests on what ros_peer.py and board_app recorded.

  checks.py samples FILE --n N --type T --count C --mono-minus-wall NS
      FILE (ros_peer.py echo --out) holds exactly the values k = 1..N that board_app pub
      wrote (element 0 = k, other elements k*1000+i, doubles carry the write time) in
      order, none twice, and each DDS source timestamp is the ccomm write time, as the
      producer's --mono-minus-wall NS (CLOCK_MONOTONIC - CLOCK_REALTIME there) puts it on
      the wall clock (--stamp-offset-ms X: X ms after it, +/- --stamp-tolerance-ms)
  checks.py watch FILE --expect JSON
      board_app watch output: one FRESH line per expected value, in order
  checks.py stats LOG SIGNAL FIELD
      the last counter of SIGNAL in the bridge's JSON stats lines of LOG
"""
import argparse
import json
import sys


def elem(k, i, typ, count, t):
    if typ == "double" and (count == 1 or i == 1):
        return float(t)
    if typ == "bool":
        return (k + i) % 2
    return k if i == 0 else k * 1000 + i


def cmd_samples(a):
    rows = [json.loads(line) for line in open(a.file)]
    errors = []
    ks = []
    skews = []
    for r in rows:
        data = r["data"] if isinstance(r["data"], list) else [r["data"]]
        data = [int(x) if isinstance(x, bool) else x for x in data]
        if len(data) != a.count:
            errors.append("length %d, not %d" % (len(data), a.count))
            continue
        if a.type == "double":
            t = int(data[0] if a.count == 1 else data[1])
            k = None if a.count == 1 else int(data[0])
            # source timestamp (wall) = write time (the producer's monotonic clock) moved to
            # the wall clock (plus --stamp-offset-ms: an arrival stamp is that much later)
            skew_ms = (r["src_ts"] - (t - a.mono_minus_wall)) / 1e6
            skews.append(skew_ms)
            if abs(skew_ms - a.stamp_offset_ms) > a.stamp_tolerance_ms:
                errors.append("source timestamp %.3f ms off the write time (want %.1f +/- %.1f)"
                              % (skew_ms, a.stamp_offset_ms, a.stamp_tolerance_ms))
        else:
            t, k = 0, int(data[0])
        if a.type == "bool":
            k = None
        if k is not None:
            ks.append(k)
            want = [elem(k, i, a.type, a.count, t) for i in range(a.count)]
            if [float(x) for x in data] != [float(x) for x in want]:
                errors.append("k=%d: values %s, want %s" % (k, data[:4], want[:4]))
    if ks:
        if ks != list(range(1, a.n + 1)):
            dup = len(ks) - len(set(ks))
            missing = sorted(set(range(1, a.n + 1)) - set(ks))
            errors.append("%d values, %d twice, %d missing (first %s), in order: %s" % (
                len(ks), dup, len(missing), missing[:5], ks == sorted(ks)))
    elif len(rows) != a.n:
        errors.append("%d values, want %d" % (len(rows), a.n))
    for e in errors[:10]:
        print("#   " + e)
    stamps = ""
    if skews:
        skews.sort()
        stamps = "; source timestamp - write time: median %.3f ms, range %.3f .. %.3f ms" % (
            skews[len(skews) // 2], skews[0], skews[-1])
    print("# %d samples checked, %d problems%s" % (len(rows), len(errors), stamps))
    return 1 if errors else 0


def cmd_watch(a):
    want = json.loads(a.expect)
    got = []
    for line in open(a.file):
        f = line.split()
        if len(f) < 5 or not f[0].isdigit():
            continue
        if f[1] != "CCOMM_FRESH" and f[1] != "fresh":
            print("#   status %s" % f[1])
            return 1
        got.append([float(x) for x in f[4:]])
    want = [[float(x) for x in (w if isinstance(w, list) else [w])] for w in want]
    if got != want:
        print("#   got %s, want %s" % (got[:6], want[:6]))
        return 1
    return 0


def cmd_stats(a):
    last = None
    for line in open(a.file, errors="replace"):
        if line.startswith("{"):
            try:
                last = json.loads(line)
            except ValueError:
                pass
    if last is None:
        print("none")
        return 1
    print(last["signals"][a.signal][a.field] if a.signal != "-" else last[a.field])
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("samples")
    s.add_argument("file")
    s.add_argument("--n", type=int, required=True)
    s.add_argument("--type", required=True)
    s.add_argument("--count", type=int, default=1)
    s.add_argument("--mono-minus-wall", type=int, default=0)
    s.add_argument("--stamp-tolerance-ms", type=float, default=2.0)
    s.add_argument("--stamp-offset-ms", type=float, default=0.0)
    w = sub.add_parser("watch")
    w.add_argument("file")
    w.add_argument("--expect", required=True)
    t = sub.add_parser("stats")
    t.add_argument("file")
    t.add_argument("signal")
    t.add_argument("field")
    a = ap.parse_args()
    return {"samples": cmd_samples, "watch": cmd_watch, "stats": cmd_stats}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
