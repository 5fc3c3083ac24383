#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The dissector fed junk: tshark must exit 0, show no Lua error, and dissect each packet.

  junk.py WORKDIR [--packets N] [--seed S]

Packets, half over UDP port 47800 and half over EtherType 0x88B5: random bytes of random
length (0-1500); every truncation of the largest valid vectors; valid vectors with random
bit flips, random header and entry fields (counts, lengths, types, flags) and random
tails; plus random UDP datagrams on another port that start with the magic (the heuristic
path). Every 7th packet is cut as by a capture's snap length (1-80 bytes into the frame). Each is dissected fully (-V), once without and once with a signals.xml loaded.
"""
import argparse
import os
import random
import struct
import sys

import wslib

sys.path.insert(0, os.path.join(wslib.ROOT, "scripts"))
import wire_vectors  # noqa: E402


def mutants(rng, seeds, n):
    out = []
    big = max(seeds, key=len)
    for cut in range(len(big) + 1):  # every truncation of the largest vector
        out.append(big[:cut])
    while len(out) < n:
        kind = rng.randrange(5)
        base = bytearray(rng.choice(seeds))
        if kind == 0:  # pure noise
            out.append(bytes(rng.getrandbits(8) for _ in range(rng.randrange(0, 1501))))
            continue
        if kind == 1:  # bit flips
            for _ in range(rng.randrange(1, 8)):
                i = rng.randrange(len(base))
                base[i] ^= 1 << rng.randrange(8)
        elif kind == 2 and len(base) >= 32:  # header fields: entry_count, payload_len, flags
            off, size = rng.choice([(5, 1), (24, 2), (26, 2), (30, 2)])
            base[off:off + size] = rng.getrandbits(8 * size).to_bytes(size, "big")
        elif kind == 3 and len(base) >= 56:  # first entry: type, flags, count, value_len
            off, size = rng.choice([(34, 1), (35, 1), (36, 2), (38, 2), (44, 4)])
            base[off:off + size] = rng.getrandbits(8 * size).to_bytes(size, "big")
        else:  # random tail or cut
            if rng.random() < 0.5:
                base = base[:rng.randrange(len(base) + 1)]
            else:
                base += bytes(rng.getrandbits(8) for _ in range(rng.randrange(1, 64)))
        out.append(bytes(base))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("workdir")
    ap.add_argument("--packets", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=None)
    args = ap.parse_args()
    seed = args.seed if args.seed is not None else random.SystemRandom().randrange(1 << 32)
    rng = random.Random(seed)
    print("# junk: seed %d (rerun with --seed %d), %d packets" % (seed, seed, args.packets))
    ts = wslib.Tshark(args.workdir)
    seeds = [v.data() for v in wire_vectors.vectors()]
    frames = mutants(rng, seeds, args.packets)
    packets, to_ccomm, snaplens = [], 0, []
    for i, fr in enumerate(frames):
        heuristic = i % 10 == 9  # another UDP port, a frame starting with the magic
        if heuristic:
            fr = struct.pack(">IB", wire_vectors.MAGIC, wire_vectors.VERSION) + fr[5:]
            packets.append(wslib.udp(fr, port=40000 + i % 1000))
        else:
            packets.append(wslib.udp(fr) if i % 2 else wslib.ethernet(fr))
        # every 7th packet as a capture with a short snap length saw it: cut 1-80 bytes
        # into the ccomm frame (a cut before it leaves the frame to no dissector)
        cut = rng.randrange(1, 81) if i % 7 == 6 else 65535
        snaplens.append(len(packets[-1]) - len(fr) + cut)
        # an empty payload goes to no dissector; the heuristic wants 8 bytes to judge
        to_ccomm += min(len(fr), cut) >= 8 if heuristic else len(fr) > 0
    pcap = os.path.join(args.workdir, "junk.pcap")
    wslib.write_pcap(pcap, packets, snaplens)
    config = ts.config(os.path.join(wslib.ROOT, "dist", "signals.xml"))
    failed = 0
    for label, extra in (("no configuration", []), ("with dist/signals.xml", ["-o", config])):
        r = ts.run(["-n", "-r", ts.readable(pcap), "-V"] + extra, check=False, timeout=600)
        roots = sum(1 for line in r.stdout.splitlines() if line.startswith("ccomm signal frames"))
        lua_errors = [line.strip() for line in r.stdout.splitlines() + r.stderr.splitlines()
                      if "Lua Error" in line or "lua_error" in line.lower()]
        problems = []
        if r.returncode != 0:
            problems.append("tshark exit %d: %s" % (r.returncode, r.stderr.strip()[-500:]))
        if lua_errors:
            problems.append("%d Lua errors, first: %s" % (len(lua_errors), lua_errors[0]))
        if roots != to_ccomm:
            problems.append("%d of %d packets reached the dissector" % (roots, to_ccomm))
        if problems:
            failed = 1
            print("not ok - junk, %s: %s (seed %d)" % (label, "; ".join(problems), seed))
        else:
            print("ok - junk, %s: %d packets dissected, tshark exit 0, no Lua error" % (label, roots))
    return failed


if __name__ == "__main__":
    sys.exit(main())
