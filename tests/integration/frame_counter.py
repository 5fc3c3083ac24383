# SPDX-License-Identifier: Apache-2.0
"""Counts the ccomm UDP frames on `lo` for SECONDS with a packet socket (what really went
on the wire, independent of ccommd's counters) and prints one JSON object:
{"seconds": S, "counts": {"SENDER:KIND:DEST": N}}, KIND data/heartbeat/summary. Run it in
the namespace of the daemons (test_system_view.py).

    python3 frame_counter.py PORT SECONDS
"""
import json
import socket
import struct
import sys
import time

port, seconds = int(sys.argv[1]), float(sys.argv[2])
s = socket.socket(socket.AF_PACKET, socket.SOCK_DGRAM, socket.htons(0x0800))
s.bind(("lo", 0))
s.settimeout(0.05)
print(json.dumps({"ready": True}), flush=True)
counts = {}
start = time.monotonic()
while time.monotonic() - start < seconds:
    try:
        pkt, addr = s.recvfrom(4096)
    except socket.timeout:
        continue
    if addr[2] == socket.PACKET_OUTGOING:
        continue  # lo shows every packet twice: count it once, as received
    ihl = (pkt[0] & 15) * 4
    if pkt[9] != 17 or struct.unpack(">H", pkt[ihl + 2:ihl + 4])[0] != port:
        continue
    frame = pkt[ihl + 8:]
    if len(frame) < 32 or frame[:4] != b"CCMW":
        continue
    flags, sender, dest = frame[5], struct.unpack(">H", frame[6:8])[0], struct.unpack(">H", frame[28:30])[0]
    kind = "summary" if flags & 4 else "heartbeat" if flags & 1 else "data"
    key = "%d:%s:%d" % (sender, kind, dest)
    counts[key] = counts.get(key, 0) + 1
print(json.dumps({"seconds": time.monotonic() - start, "counts": counts}), flush=True)
