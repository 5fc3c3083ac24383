#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Checks one impairment phase of netem.sh exactly, from two snapshots.

A snapshot (taken while tests/reliability/impair.c holds every frame, so nothing is in
flight) is a directory with planner.json and control.json (`ccomm stats --json`),
imp.json (impair's counters) and drops.json (frames dropped at each ccommd's socket).

  phase_check.py KIND AUTH PREV2 PREV CUR

KIND is loss|dup|reorder|corrupt|jitter|all|clean; AUTH 1 if frames carry a MAC. PREV2
is the snapshot before PREV ("-" if none): the frames impair held during PREV's pause
were lost, and the receivers see that gap in this phase.

Prints "CHECK 0|1 text" and "FIGURE text" lines for the TAP driver."""
import json
import os
import sys

FRAME_COUNTERS = ("frames_rx", "frames_bad", "frames_wrong_hash", "frames_unknown_sender",
                  "frames_auth_failed", "frames_replayed", "frames_not_for_us")


def load(d):
    if d == "-":
        return None
    snap = {}
    for name in ("planner", "control", "imp", "drops"):
        with open(os.path.join(d, name + ".json")) as f:
            snap[name] = json.loads(f.read().strip().splitlines()[-1])
    return snap


def main():
    kind, auth = sys.argv[1], sys.argv[2] == "1"
    prev2, prev, cur = (load(d) for d in sys.argv[3:6])
    out = []

    def check(ok, text):
        out.append("CHECK %d %s" % (1 if ok else 0, text))

    # receiver node, the sender's direction in impair, the receiver's socket drops
    for node, direction, sender in (("planner", "a2b", "control"), ("control", "b2a", "planner")):
        def delta(get):
            return get(cur) - get(prev)
        counters = lambda s, k: s[node]["counters"][k]
        peer = lambda s, k: s[node]["peers"][0][k]
        imp = lambda s, k: s["imp"][direction][k]
        d_imp = {k: delta(lambda s, k=k: imp(s, k)) for k in cur["imp"][direction]}
        d_cnt = {k: delta(lambda s, k=k: counters(s, k)) for k in FRAME_COUNTERS}
        d_peer = {k: delta(lambda s, k=k: peer(s, k)) for k in ("frames_lost", "frames_reordered", "frames_rx")}
        drops = delta(lambda s: s["drops"][node])
        held_before = (imp(prev, "held") - imp(prev2, "held")) if prev2 else imp(prev, "held")
        tag = "%s %s->%s" % (kind, sender, node)
        total = sum(d_cnt.values())
        out.append("FIGURE %s: impair in %d, dropped %d, dup %d, reordered %d, corrupted %d, delivered %d; "
                   "ccommd rx %d, bad %d, auth_failed %d, replayed %d; peer lost %d, reordered %d; "
                   "socket drops %d; held at the previous pause %d" % (
                       tag, d_imp["in"], d_imp["dropped"], d_imp["duplicated"], d_imp["reordered"],
                       d_imp["corrupted"], d_imp["delivered"], d_cnt["frames_rx"], d_cnt["frames_bad"],
                       d_cnt["frames_auth_failed"], d_cnt["frames_replayed"], d_peer["frames_lost"],
                       d_peer["frames_reordered"], drops, held_before))
        check(d_imp["delivered"] == total + drops and d_imp["overflow"] == 0 and d_imp["send_errors"] == 0,
              "%s: every frame delivered is counted once (%d == %d + %d socket drops)"
              % (tag, d_imp["delivered"], total, drops))
        if drops:
            continue  # the finer identities below assume no socket drop (none expected here)
        lost, reord = d_peer["frames_lost"], d_peer["frames_reordered"]
        replayed = d_cnt["frames_replayed"]
        rejected = d_cnt["frames_bad"] + d_cnt["frames_auth_failed"]
        if kind in ("loss", "clean"):
            check(lost == d_imp["dropped"] + held_before and reord == 0 and replayed == 0,
                  "%s: frames lost == dropped + held (%d == %d + %d)" % (tag, lost, d_imp["dropped"], held_before))
        elif kind == "dup":
            dups = replayed if auth else reord
            check(dups == d_imp["duplicated"] and lost == held_before and rejected == 0,
                  "%s: every duplicate is refused as %s (%d == %d), nothing lost"
                  % (tag, "a replay" if auth else "a duplicate", dups, d_imp["duplicated"]))
            if auth:
                check(reord == 0, "%s: no duplicate reached the sequence check (%d)" % (tag, reord))
        elif kind in ("reorder", "jitter"):
            # A frame overtaken by a later one is first counted lost (the gap), then arrives
            # late: accepted as reordered, or (auth) refused as a replay if it fell more than
            # the replay window behind. Nothing is lost for good.
            late = reord + (replayed if auth else 0)
            check(lost == held_before + late and rejected == 0 and (auth or replayed == 0),
                  "%s: frames lost == held + arrived late (%d == %d + %d)" % (tag, lost, held_before, late))
            if kind == "reorder" and direction == "a2b":  # b2a is too sparse to overtake
                check(d_imp["reordered"] == 0 or late > 0,
                      "%s: reordering was seen (%d frames sent early, %d arrived late)"
                      % (tag, d_imp["reordered"], late))
        elif kind == "corrupt":
            check(rejected == d_imp["corrupted"] and lost == held_before + d_imp["corrupted"],
                  "%s: every corrupted frame is rejected (bad %d + auth_failed %d == corrupted %d) and"
                  " counted lost" % (tag, d_cnt["frames_bad"], d_cnt["frames_auth_failed"], d_imp["corrupted"]))
    print("\n".join(out))


if __name__ == "__main__":
    main()
