#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The dissector against ccommd's own decoder on the same junk: which frames are malformed.

  differential.py WORKDIR [--frames N] [--seed S]     (root; exit 4 otherwise)

One ccommd (planner, dist/signals.xml) in a network namespace; from the other end of the
veth pair this script sends the protocol.md vectors, random valid frames (every type,
arrays, events, tags) each also with one byte replaced, and junk.py's noise, truncations
and mutations; first over UDP, then as raw Ethernet frames. The same bytes go through
tshark with the dissector. The frames it finds valid are sent first: ccommd's frames_bad
must not move; then the ones it flags: frames_bad must grow by exactly their number
(less those the kernel dropped at ccommd's socket on a busy machine, at most 5 %). So
both implementations draw the line between valid and malformed in the same place,
frame by frame, Ethernet padding included.
"""
import argparse
import os
import random
import re
import socket
import struct
import subprocess
import sys
import time

import wslib
from junk import mutants
from live import import_harness

sys.path.insert(0, os.path.join(wslib.ROOT, "scripts"))
import wire_vectors  # noqa: E402


def send_main(mode, target, path):
    """Runs inside the sending namespace: each length-prefixed frame in `path`, paced so
    the receiver's socket buffer never overflows."""
    data = open(path, "rb").read()
    frames, off = [], 0
    while off < len(data):
        (n,) = struct.unpack_from(">H", data, off)
        frames.append(data[off + 2:off + 2 + n])
        off += 2 + n
    if mode == "udp":
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        for i, fr in enumerate(frames):
            s.sendto(fr, (target, wslib.UDP_PORT))
            if i % 25 == 24:
                time.sleep(0.01)
    else:
        s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW)
        s.bind((target, 0))
        for i, fr in enumerate(frames):
            s.send(fr)
            if i % 25 == 24:
                time.sleep(0.01)
    return 0


def structured(rng, n):
    """Valid frames of random content (types, arrays, kinds, values, tags), each also with
    one byte replaced: frames right at the line between valid and malformed."""
    out = []
    for i in range(n // 2):
        entries = []
        for _ in range(rng.randrange(1, 6)):
            tname = rng.choice(list(wire_vectors.TYPES))
            count = rng.randrange(1, 9)
            if tname == "bool":
                values = [rng.randrange(2) for _ in range(count)]
            elif tname in ("float", "double"):
                values = [rng.uniform(-1e6, 1e6) for _ in range(count)]
            else:
                bits = 32 if tname.endswith("32") else 64
                lo = -(1 << (bits - 1)) if not tname.startswith("u") else 0
                values = [rng.randrange(lo, lo + (1 << bits)) for _ in range(count)]
            entries.append(wire_vectors.Entry(rng.randrange(65536), tname, values, flags=rng.randrange(2),
                                              seq=rng.randrange(1 << 32), time_ns=rng.randrange(1 << 63)))
        heartbeat = rng.random() < 0.2
        frame = wire_vectors.Frame("random", "ok", sender=rng.randrange(65536), dest=rng.randrange(65536),
                                   config_hash=rng.randrange(1 << 32), seq=rng.randrange(1 << 32),
                                   time_ns=rng.randrange(1 << 63), flags=1 if heartbeat else 0,
                                   entries=[] if heartbeat else entries).data()
        if not heartbeat and rng.random() < 0.2:  # with a tag
            frame = frame[:5] + bytes([frame[5] | 2]) + frame[6:] + bytes(rng.getrandbits(8) for _ in range(16))
        broken = bytearray(frame)
        broken[rng.randrange(len(broken))] = rng.getrandbits(8)
        out += [frame, bytes(broken)]
    return out


def frames_bad(pair):
    return pair.stats("planner")["counters"]["frames_bad"]


def socket_drops(pair):
    """Frames the kernel dropped at ccommd's sockets (receive buffer full: a busy machine),
    from ss's skmem d<N>, like tests/reliability/lib.sh's sock_drops."""
    pid = "pid=%d," % pair.daemons["planner"].pid
    out = subprocess.run(pair.exec_prefix("planner") + ["ss", "-a", "-n", "-p", "-m", "-0", "-u"],
                         capture_output=True, text=True).stdout
    drops, want = 0, False
    for line in out.splitlines():
        if pid in line:
            want = True
        m = re.search(r",d(\d+)\)", line) if want and "skmem" in line else None
        if m:
            drops, want = drops + int(m.group(1)), False
    return drops


def settle(pair, timeout=10.0):
    """frames_bad once it stopped moving (the daemon has read everything sent)."""
    last, stable, deadline = frames_bad(pair), 0, time.time() + timeout
    while time.time() < deadline and stable < 3:
        time.sleep(0.1)
        now = frames_bad(pair)
        stable = stable + 1 if now == last else 0
        last = now
    return last


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--send":
        return send_main(*sys.argv[2:5])
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("workdir")
    ap.add_argument("--frames", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=None)
    args = ap.parse_args()
    if os.geteuid() != 0:
        print("# SKIP differential: needs root (network namespaces, raw sockets)")
        return 4
    seed = args.seed if args.seed is not None else random.SystemRandom().randrange(1 << 32)
    print("# differential: seed %d (rerun with --seed %d), %d frames per transport" % (seed, seed, args.frames))
    rng = random.Random(seed)
    vectors = [v.data() for v in wire_vectors.vectors()]
    junk = vectors + structured(rng, args.frames) + [f for f in mutants(rng, vectors, args.frames) if f]
    harness = import_harness()
    ts = wslib.Tshark(args.workdir)
    failed = 0
    for transport in ("udp", "raw"):
        with harness.NodePair(transport="udp" if transport == "udp" else None) as pair:
            pair.start("planner")
            ns = pair.ns["control"]
            mac = subprocess.run(["ip", "netns", "exec", ns, "cat", "/sys/class/net/eth0/address"],
                                 capture_output=True, text=True, check=True).stdout.strip()
            if transport == "udp":
                wire = [wslib.udp(f) for f in junk]
            else:  # broadcast, as ccommd sends without a configured MAC
                wire = [b"\xff" * 6 + bytes.fromhex(mac.replace(":", "")) + struct.pack(">H", wslib.ETHERTYPE) + f
                        for f in junk]
            pcap = os.path.join(args.workdir, "differential-%s.pcap" % transport)
            wslib.write_pcap(pcap, wire)
            pkts, _ = ts.fields(pcap, ["ccomm.decode_error", "_ws.lua.text"])
            if len(pkts) != len(junk) or any("_ws.lua.text" in p for p in pkts):
                print("not ok - %s: tshark dissected %d of %d frames or raised a Lua error" % (transport, len(pkts), len(junk)))
                failed = 1
                continue
            payload = wire if transport == "raw" else junk
            groups = {"valid": [w for w, p in zip(payload, pkts) if "ccomm.decode_error" not in p],
                      "malformed": [w for w, p in zip(payload, pkts) if "ccomm.decode_error" in p]}
            start, dropped = settle(pair), socket_drops(pair)
            for name in ("valid", "malformed"):
                path = os.path.join(args.workdir, "%s-%s.bin" % (transport, name))
                with open(path, "wb") as f:
                    for w in groups[name]:
                        f.write(struct.pack(">H", len(w)) + w)
                subprocess.run(["ip", "netns", "exec", ns, sys.executable, os.path.abspath(__file__), "--send",
                                transport, "10.42.0.2" if transport == "udp" else "eth0", path], check=True)
                now, drops = settle(pair), socket_drops(pair)
                lost = drops - dropped  # never reached ccommd: cannot count either way
                want = len(groups[name]) if name == "malformed" else 0
                ok = want - lost <= now - start <= want and lost <= len(groups[name]) // 20
                print("%s - %s: %d frames the dissector finds %s: ccommd's frames_bad grew by %d (expected %d%s)"
                      % ("ok" if ok else "not ok", transport, len(groups[name]), name, now - start, want,
                         ", %d dropped by the kernel before ccommd read them" % lost if lost else ""))
                failed |= not ok
                start, dropped = now, drops
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
