#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The dissector's configuration support against ccommd: for each configuration in dist/
and examples/, a frame carrying the hash `ccommd --check` prints must show no
config_mismatch with that file loaded (as `ccommd --check FILE --json` resolves it), and a
frame carrying another hash must show one.

  confighash.py WORKDIR BIN_DIR

Also the other two preferences: ccomm.udp_port and ccomm.ethertype move the dissector
to a configuration's <network udp_port=... ethertype=...>.
"""
import glob
import os
import re
import struct
import subprocess
import sys

import wslib

sys.path.insert(0, os.path.join(wslib.ROOT, "scripts"))
import wire_vectors  # noqa: E402


def heartbeat(config_hash):
    frame = bytearray(wire_vectors.vectors()[0].data())  # the heartbeat vector
    frame[8:12] = struct.pack(">I", config_hash)
    return bytes(frame)


def main():
    work, bin_dir = sys.argv[1], sys.argv[2]
    ts = wslib.Tshark(work)
    failed = 0
    configs = [os.path.join(wslib.ROOT, "dist", "signals.xml")] + \
        sorted(glob.glob(os.path.join(wslib.ROOT, "examples", "*.xml")))
    for path in configs:
        r = subprocess.run([os.path.join(bin_dir, "ccommd"), "--check", path], capture_output=True, text=True)
        m = re.search(r"hash ([0-9a-f]{8})", r.stdout)
        if not m:
            print("not ok - ccommd --check %s: %s" % (path, (r.stdout + r.stderr).strip()))
            failed = 1
            continue
        h = int(m.group(1), 16)
        pcap = os.path.join(work, "hash.pcap")
        wslib.write_pcap(pcap, [wslib.udp(heartbeat(h)), wslib.udp(heartbeat(h ^ 1))])
        pkts, _ = ts.fields(pcap, ["_ws.expert.message"], ["-o", ts.config(path)])
        msgs = [p.get("_ws.expert.message", []) for p in pkts]
        ok = len(msgs) == 2 and not msgs[0] and any(m.startswith("config_mismatch") for m in msgs[1])
        name = os.path.relpath(path, wslib.ROOT)
        print("%s - %s: the dissector's hash equals ccommd's (%08x)%s"
              % ("ok" if ok else "not ok", name, h, "" if ok else ": %s" % msgs))
        failed |= not ok
    # a bad-magic frame on another UDP port (the heuristic does not claim it) and a
    # heartbeat on another EtherType: ccomm only with the preferences set
    bad_magic = bytearray(heartbeat(0))
    bad_magic[3] ^= 0x0F
    pcap = os.path.join(work, "prefs.pcap")
    wslib.write_pcap(pcap, [wslib.udp(bytes(bad_magic), port=40001), wslib.ethernet(heartbeat(0), ethertype=0x88B6)])
    names = ["ccomm.magic"]
    plain, _ = ts.fields(pcap, names)
    moved, _ = ts.fields(pcap, names, ["-o", "ccomm.udp_port:40001", "-o", "ccomm.ethertype:%d" % 0x88B6])
    ok = [("ccomm.magic" in p) for p in plain] == [False, False] and [("ccomm.magic" in p) for p in moved] == [True, True]
    print("%s - preferences ccomm.udp_port and ccomm.ethertype move the dissector" % ("ok" if ok else "not ok"))
    failed |= not ok
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
