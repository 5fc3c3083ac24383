#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The layout rule of ccomm.h's structs, between two abidw dumps (baseline, current):
a growable struct keeps every member of the baseline at its offset and only gains members
at its end; a fixed struct (taken by a real-time call without a size) does not change at
all. abidiff's has_data_member_inserted_at suppression (allowed.suppr) lets any insertion
through (libabigail 2.2), so this check is the exact one.

    growth_check.py BASELINE.abi CURRENT.abi      exit 0 ok, 1 a struct broke the rule
"""
import sys
import xml.etree.ElementTree as ET

GROWABLE = {"ccomm_signal_desc", "ccomm_signal_stats", "ccomm_peer_stats", "ccomm_view_node",
            "ccomm_view_signal", "ccomm_view_counters", "ccomm_peer_clock", "ccomm_clock_state",
            "ccomm_production_age"}
FIXED = {"ccomm_info", "ccomm_history_cursor", "ccomm_history_info"}
# Changes made before the rule, each with why old programs still work.
EXCEPTIONS = {
    "ccomm_signal_stats": "gained `corrupt` in its middle after 0.1.0; the plain "
                          "ccomm_get_signal_stats symbol, which 0.1.0 programs call, fills the 0.1.0 "
                          "layout (client_info.cpp SignalStats010, client_test "
                          "SizedCallsServeOlderAndNewerCallers)",
}


def structs(path):
    """{name: (size in bits, [(member, offset in bits)])} of the ccomm_* structs."""
    out = {}
    for c in ET.parse(path).getroot().iter("class-decl"):
        name = c.get("name", "")
        if not name.startswith("ccomm_") or c.get("is-declaration-only") == "yes" or c.get("size-in-bits") is None:
            continue
        members = [(m.find("var-decl").get("name"), int(m.get("layout-offset-in-bits")))
                   for m in c.findall("data-member")]
        out[name] = (int(c.get("size-in-bits")), members)
    return out


def main():
    base, cur = structs(sys.argv[1]), structs(sys.argv[2])
    bad = []
    for name, (size, members) in sorted(base.items()):
        if name in ("ccomm_client", "ccomm_view"):
            continue  # opaque handles
        if name not in cur:
            bad.append(f"{name}: gone")
            continue
        csize, cmembers = cur[name]
        if name in FIXED and (csize, cmembers) != (size, members):
            bad.append(f"{name}: a fixed struct changed ({size} -> {csize} bits)")
        elif name in GROWABLE and (cmembers[:len(members)] != members or csize < size):
            if name in EXCEPTIONS:
                print(f"growth_check: {name} changed, allowed: {EXCEPTIONS[name]}")
            else:
                bad.append(f"{name}: members moved or removed (only appending is allowed): "
                           f"{members} -> {cmembers}")
        elif name not in FIXED | GROWABLE:
            bad.append(f"{name}: a public struct neither growable nor fixed (add it to ccomm.h's "
                       "list and here)")
    for b in bad:
        print("growth_check: " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
