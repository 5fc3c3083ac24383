# SPDX-License-Identifier: Apache-2.0
"""Stands in for the planner's ccommd in test_batch.py: receives ccomm UDP frames and
prints, per frame with entries, the signal ids and values it carries (decoded from
docs/protocol.md, independently of the C++ codec), one JSON line each, until SECONDS
without such a frame (heartbeats keep coming: they are not printed).

    python3 frame_sink.py IP PORT SECONDS OUT.jsonl

(The frames go to a file, not a pipe: a full pipe would stall the sink and the kernel
would drop frames at its socket.)
"""
import json
import socket
import struct
import sys
import time

ip, port, quiet = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
out = open(sys.argv[4], "w")
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
s.bind((ip, port))
s.settimeout(0.1)
print(json.dumps({"ready": True}), flush=True)
start = time.monotonic()
last = None  # the quiet time counts from the first frame with entries (at most 60 s before it)
while (time.monotonic() - last < quiet) if last is not None else (time.monotonic() - start < 60):
    try:
        data, _ = s.recvfrom(65536)
    except socket.timeout:
        continue
    if True:
        magic, _ver, flags, sender, _hash, seq, _t, count, _plen, dest, _r = struct.unpack(">IBBHIIQHHHH", data[:32])
        off, entries = 32, []
        for _ in range(count):
            sig, typ, _ef, n, vlen, vseq, _res, _st = struct.unpack(">HBBHHIIQ", data[off:off + 24])
            value = struct.unpack(">d", data[off + 24:off + 32])[0] if typ == 6 and n == 1 else None
            entries.append([sig, value])
            off += 24 + (vlen + 7) // 8 * 8
        if entries:
            last = time.monotonic()
            out.write(json.dumps({"seq": seq, "flags": flags, "entries": entries}) + "\n")
out.close()
