#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The dissector against docs/protocol.md's test vectors, in both encapsulations.

  vectors.py WORKDIR            check (exit 1 on any failure)
  vectors.py WORKDIR --update   rewrite the goldens (tests/wireshark/golden/) first

Checks, per encapsulation (UDP port 47800; raw Ethernet, EtherType 0x88B5):
- `tshark -O ccomm` output equals the committed golden (field names, values, experts);
- every valid vector decodes, without any warning or error, into the field values that
  scripts/wire_vectors.py encodes it from (header fields, each entry's fields, values);
- every malformed vector gets ccomm.decode_error = its `expect=` from the document and an
  error expert info "<expect>: ..." whose words come from the document's Validation
  section. On raw Ethernet, TrimEthernetPadding() makes trailing-byte (one zero byte after
  a 32-byte heartbeat) a padded heartbeat, so there it must decode as valid, as ccommd does.
"""
import difflib
import os
import re
import struct
import sys

import wslib

sys.path.insert(0, os.path.join(wslib.ROOT, "scripts"))
import wire_vectors  # noqa: E402  (the independent encoder of the vectors)

GOLDEN = os.path.join(wslib.HERE, "golden")
PROTOCOL = os.path.join(wslib.ROOT, "docs", "protocol.md")
TYPE_NAMES = {1: "bool", 2: "int32", 3: "uint32", 4: "int64", 5: "float", 6: "double"}
FIELDS = ["ccomm.magic", "ccomm.version", "ccomm.flags", "ccomm.sender", "ccomm.config_hash", "ccomm.seq",
          "ccomm.send_time_ns", "ccomm.entry_count", "ccomm.payload_len", "ccomm.dest", "ccomm.reserved",
          "ccomm.entry.signal", "ccomm.entry.type", "ccomm.entry.flags", "ccomm.entry.count",
          "ccomm.entry.value_len", "ccomm.entry.seq", "ccomm.entry.reserved", "ccomm.entry.source_time_ns",
          "ccomm.entry.value", "ccomm.entry.total_len", "ccomm.entry.offset", "ccomm.auth_tag", "ccomm.decode_error", "_ws.expert.message",
          "_ws.expert.severity", "_ws.malformed", "_ws.lua.text", "ccomm.summary.part", "ccomm.summary.parts",
          "ccomm.summary.record_count", "ccomm.summary.cycle_ms", "ccomm.summary.uptime_ns",
          "ccomm.summary.frames_rx", "ccomm.summary.record.signal", "ccomm.summary.record.role",
          "ccomm.summary.record.flags", "ccomm.summary.record.rate_mhz", "ccomm.summary.record.lost",
          "ccomm.summary.record.age_ms", "ccomm.summary.clock_state", "ccomm.summary.clock_error_ns",
          "ccomm.summary.clock_offset_ns"] + \
         ["ccomm.entry.value." + t for t in TYPE_NAMES.values()]
failures = []


def fail(msg):
    failures.append(msg)
    print("not ok - " + msg)


def validation_words():
    text = open(PROTOCOL, encoding="utf-8").read()
    section = text.split("### Validation", 1)[1].split("\n## ", 1)[0]
    return set(re.findall(r"[a-z_]+", section.replace("`", "").lower()))


def message_words(msg):
    """Words of an expert message, without its DecodeError prefix, entry number, details in
    parentheses and numbers: what must come from the document."""
    msg = re.sub(r"^\w+: (entry \d+: )?", "", msg)
    msg = re.sub(r"\([^)]*\)|\b0x[0-9a-fA-F]+\b|\b\d+\b", "", msg)
    return re.findall(r"[a-z_]+", msg.lower())


def expected_frame(v):
    """What the dissector must show for a valid vector, from the encoder's inputs."""
    data = v.data()
    exp = {"ccomm.magic": "0x43434d57", "ccomm.version": str(wire_vectors.VERSION), "ccomm.flags": "0x%02x" % v.flags,
           "ccomm.sender": str(v.sender), "ccomm.config_hash": "0x%08x" % v.config_hash,
           "ccomm.seq": str(v.seq), "ccomm.send_time_ns": str(v.time_ns),
           "ccomm.entry_count": str(len(v.entries)), "ccomm.payload_len": str(len(data) - 32 - (16 if v.tag else 0)),
           "ccomm.dest": str(v.dest), "ccomm.reserved": "0x0000"}
    if v.tag:
        exp["ccomm.auth_tag"] = v.tag.hex()
    return exp


def check_valid(pkt, v, where):
    for k, want in expected_frame(v).items():
        got = pkt.get(k, [None])
        if got != [want]:
            fail("%s: %s = %s, expected %s" % (where, k, got, want))
    n = len(v.entries)
    def entry_field(k):
        return pkt.get(k, [])
    for k, want in (("ccomm.entry.signal", [str(e.signal) for e in v.entries]),
                    ("ccomm.entry.type", [str(wire_vectors.TYPES[e.tname][0]) for e in v.entries]),
                    ("ccomm.entry.flags", ["0x%02x" % (e.flags | (wire_vectors.E_FRAGMENT if frag(e) else 0))
                                           for e in v.entries]),
                    ("ccomm.entry.count", [str(e.whole if frag(e) else len(e.values)) for e in v.entries]),
                    ("ccomm.entry.total_len", [str(e.whole * wire_vectors.TYPES[e.tname][1]) for e in v.entries
                                               if frag(e)]),
                    ("ccomm.entry.offset", [str(e.offset) for e in v.entries if frag(e)]),
                    ("ccomm.entry.value_len", [str(len(e.values) * wire_vectors.TYPES[e.tname][1]) for e in v.entries]),
                    ("ccomm.entry.seq", [str(e.seq) for e in v.entries]),
                    ("ccomm.entry.reserved", ["0x00000000"] * n),
                    ("ccomm.entry.source_time_ns", [str(e.time_ns) for e in v.entries])):
        if entry_field(k) != want:
            fail("%s: %s = %s, expected %s" % (where, k, entry_field(k), want))
    if v.summary:  # a node summary: its head and records as the encoder wrote them
        sm = v.summary
        recs = sm.records
        for k, want in (("ccomm.summary.part", [str(sm.part)]), ("ccomm.summary.parts", [str(sm.parts)]),
                        ("ccomm.summary.record_count", [str(len(recs))]),
                        ("ccomm.summary.cycle_ms", [str(sm.cycle_ms)]),
                        ("ccomm.summary.uptime_ns", [str(sm.uptime_ns)]),
                        ("ccomm.summary.frames_rx", [str(sm.counters[0])]),
                        ("ccomm.summary.clock_state", [str(sm.clock[0])]),
                        ("ccomm.summary.clock_error_ns", [str(sm.clock[1])]),
                        ("ccomm.summary.clock_offset_ns", [str(sm.clock[2])]),
                        ("ccomm.summary.record.signal", [str(r[0]) for r in recs]),
                        ("ccomm.summary.record.role", [str(r[1]) for r in recs]),
                        ("ccomm.summary.record.flags", ["0x%02x" % r[2] for r in recs]),
                        ("ccomm.summary.record.rate_mhz", [str(r[3]) for r in recs]),
                        ("ccomm.summary.record.lost", [str(r[4]) for r in recs]),
                        ("ccomm.summary.record.age_ms", [str(r[5]) for r in recs])):
            if entry_field(k) != want:
                fail("%s: %s = %s, expected %s" % (where, k, entry_field(k), want))
    # values: the text field and the typed elements, compared as numbers of their type
    texts = entry_field("ccomm.entry.value")
    typed = {t: list(entry_field("ccomm.entry.value." + t)) for t in TYPE_NAMES.values()}
    for i, e in enumerate(v.entries):
        shown = texts[i].split(", ") if i < len(texts) else []
        elems = [typed[e.tname].pop(0) if typed[e.tname] else None for _ in e.values]
        for j, want in enumerate(e.values):
            # the text is exact; the typed field's text is tshark's (15 digits for a double)
            if not same_value(e.tname, shown[j] if j < len(shown) else None, want) or \
               not same_value(e.tname, elems[j], want, rel=1e-14):
                fail("%s: entry %d element %d: value %r / typed %r, expected %r"
                     % (where, i, j, shown[j] if j < len(shown) else None, elems[j], want))
                break  # one line per entry is enough
    for sev in pkt.get("_ws.expert.severity", []):
        if int(sev) >= 0x00600000:  # PI_WARN and above
            fail("%s: valid frame has expert info %s" % (where, pkt.get("_ws.expert.message")))
    if "ccomm.decode_error" in pkt or "_ws.malformed" in pkt or "_ws.lua.text" in pkt:
        fail("%s: valid frame flagged: %s %s" % (where, pkt.get("ccomm.decode_error"), pkt.get("_ws.lua.text")))


def frag(e):
    return isinstance(e, wire_vectors.Fragment)


def same_value(tname, text, want, rel=0.0):
    if text is None:
        return False
    if tname == "bool":
        return text.lower() in (("true", "1") if want else ("false", "0"))
    if tname in ("float", "double"):
        got = float(text)
        if tname == "float":  # the wire carries binary32: compare after the same rounding
            want = struct.unpack(">f", struct.pack(">f", want))[0]
            got = struct.unpack(">f", struct.pack(">f", got))[0]
        return got == want or abs(got - want) <= rel * abs(want)
    return int(text, 0) == want


def check_malformed(pkt, name, expect, where, vocabulary):
    if pkt.get("ccomm.decode_error") != [expect]:
        fail("%s: ccomm.decode_error = %s, expected %s" % (where, pkt.get("ccomm.decode_error"), expect))
    msgs = [m for m, s in zip(pkt.get("_ws.expert.message", []), pkt.get("_ws.expert.severity", []))
            if int(s) >= 0x00800000 and m.startswith(expect + ": ")]
    if not msgs:
        fail("%s (%s): no error expert info '%s: ...' (got %s)" % (where, name, expect, pkt.get("_ws.expert.message")))
    for m in msgs:
        unknown = [w for w in message_words(m) if w not in vocabulary]
        if unknown:
            fail("%s: expert text '%s' has words not in protocol.md's Validation section: %s" % (where, m, unknown))
    if "_ws.lua.text" in pkt:
        fail("%s: Lua error: %s" % (where, pkt["_ws.lua.text"]))


def golden(ts, pcap, name, update, extra=()):
    out = ts.run(["-n", "-r", ts.readable(pcap), "-O", "ccomm"] + list(extra)).stdout
    path = os.path.join(GOLDEN, name)
    if update:
        with open(path, "w") as f:
            f.write(out)
        print("# wrote %s" % os.path.relpath(path, wslib.ROOT))
        return
    want = open(path).read() if os.path.exists(path) else ""
    if out != want:
        diff = "".join(list(difflib.unified_diff(want.splitlines(True), out.splitlines(True),
                                                 "golden/" + name, "tshark output"))[:60])
        fail("%s differs from the golden (regenerate with tests/wireshark/run --update if intended):\n%s"
             % (name, diff))
    else:
        print("ok - tshark -O ccomm output equals golden/%s" % name)


def config_frames():
    """Frames to show the signals.xml support (golden vectors-config.txt, dist/signals.xml
    loaded): a valid frame control -> planner; one whose entries break receiver rule 6
    (a signal produced by the planner, a double sent as float, an unknown signal); a
    heartbeat with another config_hash."""
    e = wire_vectors.Entry
    ok = wire_vectors.Frame("names", "ok", sender=0, dest=1, config_hash=DIST_HASH, seq=1, time_ns=10**9,
                            entries=[e(0, "double", [0.5], seq=1, time_ns=10**9), e(35, "double", [-1.5], seq=1,
                                                                                   time_ns=10**9)])
    bad = wire_vectors.Frame("bad-signal", "ok", sender=0, dest=1, config_hash=DIST_HASH, seq=2, time_ns=2 * 10**9,
                             entries=[e(36, "double", [1.0], seq=2), e(1, "float", [2.5], seq=2),
                                      e(45, "double", [3.0], seq=2)])
    other = wire_vectors.Frame("other-hash", "ok", sender=1, dest=0xFFFF, config_hash=DIST_HASH ^ 1, seq=3,
                               time_ns=3 * 10**9, flags=wire_vectors.F_HEARTBEAT)
    return [ok.data(), bad.data(), other.data()]


DIST_HASH = 0xFB9A98FC  # ccommd --check dist/signals.xml (confighash.py checks the Lua side)


def main():
    work = sys.argv[1]
    update = "--update" in sys.argv[2:]
    ts = wslib.Tshark(work)
    print("# tshark %s" % ts.how)
    doc = wire_vectors.parse_doc(open(PROTOCOL, encoding="utf-8").read())
    encoded = {v.name: v for v in wire_vectors.vectors()}
    names = list(doc)
    vocabulary = validation_words()
    if set(names) != set(encoded):
        fail("protocol.md and wire_vectors.py name different vectors: %s" % sorted(set(names) ^ set(encoded)))
        return 1
    max_frame = wire_vectors.Frame("max-frame", "ok", sender=1, dest=0, config_hash=wire_vectors.HASH, seq=1,
                                   time_ns=1, entries=[wire_vectors.Entry(1, "double", [float(i) for i in range(177)])])
    heartbeat = encoded["heartbeat"]
    for encap in ("udp", "eth"):
        wrap = wslib.udp if encap == "udp" else wslib.ethernet
        # every vector of the document, then the largest frame, then (raw only) a
        # heartbeat as Ethernet delivers it: zero-padded to 46 bytes
        frames = [doc[n][1] for n in names] + [max_frame.data()]
        cases = [(n, doc[n][0]) for n in names] + [("max-frame", "ok")]
        if encap == "eth":
            frames.append(heartbeat.data().ljust(46, b"\0"))
            cases.append(("eth-padded-heartbeat", "ok"))
        pcap = os.path.join(work, "vectors-%s.pcap" % encap)
        wslib.write_pcap(pcap, [wrap(f) for f in frames])
        golden(ts, pcap, "vectors-%s.txt" % encap, update)
        pkts, err = ts.fields(pcap, FIELDS)
        if len(pkts) != len(cases):
            fail("%s: tshark shows %d packets, wrote %d (%s)" % (encap, len(pkts), len(cases), err.strip()))
            continue
        before, valid = len(failures), 0
        for pkt, (name, expect) in zip(pkts, cases):
            where = "%s/%s" % (encap, name)
            if encap == "eth" and name == "trailing-byte":
                expect, name = "ok", "heartbeat"  # one zero byte after 32: Ethernet padding
            if name == "eth-padded-heartbeat":
                name = "heartbeat"
            if expect == "ok":
                valid += 1
                check_valid(pkt, max_frame if name == "max-frame" else encoded[name], where)
            else:
                check_malformed(pkt, name, expect, where, vocabulary)
        if len(failures) == before:
            print("ok - %s: %d valid vectors decode into the encoder's fields, %d malformed ones flagged "
                  "with their DecodeError" % (encap, valid, len(cases) - valid))
    pcap = os.path.join(work, "vectors-config.pcap")
    wslib.write_pcap(pcap, [wslib.udp(f) for f in config_frames()])
    golden(ts, pcap, "vectors-config.txt", update,
           ["-o", ts.config(os.path.join(wslib.ROOT, "dist", "signals.xml"))])
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
