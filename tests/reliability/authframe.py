#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Sends one authenticated ccomm heartbeat over raw Ethernet, built independently of the
C++ code from docs/protocol.md (header layout, flags bit 1, 16-byte tag = keyed
BLAKE2b-128 of the frame before it). Used by auth.sh to check interoperability and the
rejection of bad tags, replays and unknown senders."""
import argparse
import hashlib
import socket
import struct
import time

MAGIC, VERSION, FLAG_HEARTBEAT, FLAG_AUTH = 0x43434D57, 2, 0x01, 0x02


def frame(sender, dest, config_hash, seq, send_ns, key, flip_tag=False):
    header = struct.pack(">IBBHIIQHHHH", MAGIC, VERSION, FLAG_HEARTBEAT | FLAG_AUTH, sender, config_hash, seq,
                         send_ns, 0, 0, dest, 0)
    assert len(header) == 32
    tag = bytearray(hashlib.blake2b(header, key=key, digest_size=16).digest())
    if flip_tag:
        tag[0] ^= 0x01
    return header + bytes(tag)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ifname", required=True)
    ap.add_argument("--ethertype", type=lambda s: int(s, 0), default=0x88B5)
    ap.add_argument("--key", required=True, help="key file (32 raw bytes)")
    ap.add_argument("--sender", type=int, required=True)
    ap.add_argument("--dest", type=int, required=True)
    ap.add_argument("--hash", type=lambda s: int(s, 16), required=True)
    ap.add_argument("--seq", type=int, default=1 << 20)
    ap.add_argument("--send-ns", type=int, default=0, help="default: now (CLOCK_MONOTONIC)")
    ap.add_argument("--flip-tag", action="store_true")
    ap.add_argument("--times", type=int, default=1, help="send the same frame N times")
    a = ap.parse_args()
    key = open(a.key, "rb").read()
    f = frame(a.sender, a.dest, a.hash, a.seq, a.send_ns or time.monotonic_ns(), key, a.flip_tag)
    s = socket.socket(socket.AF_PACKET, socket.SOCK_DGRAM, socket.htons(a.ethertype))
    for _ in range(a.times):
        s.sendto(f, (a.ifname, a.ethertype, 0, 0, b"\xff" * 6))
    print(f.hex())


if __name__ == "__main__":
    main()
