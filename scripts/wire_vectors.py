#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Independent (Python `struct`) encoder of the ccomm wire format test vectors.

It shares no code with src/wire/: it encodes every vector from its field values and
checks that docs/protocol.md holds exactly these bytes, so a second implementation
agrees with the document (and wire_test checks the C++ codec against the same text).

  scripts/wire_vectors.py              check docs/protocol.md (exit 1 on any mismatch)
  scripts/wire_vectors.py --emit       print the vector blocks in the document's format
  scripts/wire_vectors.py --corpus DIR write every vector as a binary file (fuzz seeds)
  scripts/wire_vectors.py --reassembly-corpus DIR   seeds of fuzz_reassembly (fragment streams)
"""
import argparse
import os
import re
import struct
import sys

MAGIC = 0x43434D57
VERSION = 2
F_HEARTBEAT, F_AUTH, F_SUMMARY = 0x01, 0x02, 0x04
CLOCK_STATES = {0: "none", 1: "syncing", 2: "synced", 3: "lost"}
ROLES = {1: "producer", 2: "consumer"}
E_EVENT, E_FRAGMENT = 0x01, 0x02

# name: (code, element size, struct format)
TYPES = {
    "bool": (1, 1, "B"),
    "int32": (2, 4, "i"),
    "uint32": (3, 4, "I"),
    "int64": (4, 8, "q"),
    "float": (5, 4, "f"),
    "double": (6, 8, "d"),
}


def h(fmt, v):
    return struct.pack(">" + fmt, v)


class Entry:
    """One entry; keyword overrides produce malformed variants."""

    def __init__(self, signal, tname, values, flags=0, seq=0, time_ns=0, **bad):
        self.signal, self.tname, self.values = signal, tname, values
        self.flags, self.seq, self.time_ns, self.bad = flags, seq, time_ns, bad

    def lines(self):
        code, size, fmt = TYPES[self.tname]
        code = self.bad.get("type", code)
        count = self.bad.get("count", len(self.values))
        value = b"".join(h(fmt, v) for v in self.values)
        vlen = self.bad.get("value_len", len(value))
        pad = self.bad.get("padding", bytes(-len(value) % 8))
        head = [h("H", self.signal), h("B", code), h("B", self.flags), h("H", count),
                h("H", vlen), h("I", self.seq), h("I", self.bad.get("reserved", 0))]
        tname = next((n for n, t in TYPES.items() if t[0] == code), "unknown")
        kind = "event" if self.flags & E_EVENT else "state"
        shown = ", ".join(fmt_value(self.tname, v) for v in self.values)
        return [
            (head, "entry: signal %d, type %d (%s), flags %#04x (%s), count %d, value_len %d, seq %d, reserved %#x"
             % (self.signal, code, tname, self.flags, kind, count, vlen, self.seq,
                self.bad.get("reserved", 0))),
            ([h("Q", self.time_ns)], "source_time_ns %d" % self.time_ns),
            ([h(fmt, v) for v in self.values] + ([pad] if pad else []),
             "value %s%s" % (shown, "" if not pad else " + %d padding bytes%s"
                             % (len(pad), " (not zero)" if any(pad) else ""))),
        ]


class Fragment(Entry):
    """A fragment entry: `values` are the part's elements, `whole` the value's count."""

    def __init__(self, signal, tname, values, whole, offset, **kw):
        Entry.__init__(self, signal, tname, values, **kw)
        self.whole, self.offset = whole, offset

    def lines(self):
        code, size, fmt = TYPES[self.tname]
        count = self.bad.get("count", self.whole)
        value = b"".join(h(fmt, v) for v in self.values)
        vlen = self.bad.get("value_len", len(value))
        total = self.bad.get("total", self.whole * size)
        pad = bytes(-len(value) % 8)
        flags = self.flags | E_FRAGMENT
        kind = "event" if self.flags & E_EVENT else "state"
        head = [h("H", self.signal), h("B", code), h("B", flags), h("H", count),
                h("H", vlen), h("I", self.seq), h("I", 0)]
        shown = ", ".join(fmt_value(self.tname, v) for v in self.values)
        return [
            (head, "entry: signal %d, type %d (%s), flags %#04x (%s, fragment), count %d, value_len %d, seq %d, reserved 0x0"
             % (self.signal, code, self.tname, flags, kind, count, vlen, self.seq)),
            ([h("Q", self.time_ns)], "source_time_ns %d" % self.time_ns),
            ([h("I", total), h("I", self.offset)], "fragment: total_len %d, offset %d" % (total, self.offset)),
            ([h(fmt, v) for v in self.values] + ([pad] if pad else []),
             "part %s%s" % (shown, "" if not pad else " + %d padding bytes" % len(pad))),
        ]


class Summary:
    """A node summary body (docs/protocol.md, "Node summary"): head, then records
    (signal, role, flags, rate_mhz, lost, age_ms); keyword overrides make bad ones."""

    def __init__(self, part, parts, cycle_ms, uptime_ns, peers_alive, counters, records,
                 clock=(0, 0xFFFFFFFF, 0), **bad):
        self.part, self.parts, self.cycle_ms, self.uptime_ns = part, parts, cycle_ms, uptime_ns
        self.peers_alive, self.counters, self.records, self.bad = peers_alive, counters, records, bad
        self.clock = clock  # (clock_state, clock_error_ns, clock_offset_ns)

    def lines(self):
        n = self.bad.get("record_count", len(self.records))
        rx, tx, bad, lost, drops = self.counters
        out = [
            ([h("B", self.part), h("B", self.parts), h("H", n), h("I", self.cycle_ms)],
             "summary: part %d of %d, record_count %d, cycle_ms %d" % (self.part, self.parts, n, self.cycle_ms)),
            ([h("Q", self.uptime_ns)], "uptime_ns %d" % self.uptime_ns),
            ([h("Q", self.peers_alive)], "peers_alive %#x" % self.peers_alive),
            ([h("Q", rx), h("Q", tx)], "frames_rx %d, frames_tx %d" % (rx, tx)),
            ([h("Q", bad), h("Q", lost), h("Q", drops)], "frames_bad %d, frames_lost %d, socket_drops %d"
             % (bad, lost, drops)),
        ]
        state, error, offset = self.clock
        reserved = self.bad.get("clock_reserved", 0)
        out += [
            ([h("B", state), h("B", reserved), h("H", 0), h("I", error)],
             "clock_state %d (%s), reserved %#x, clock_error_ns %s"
             % (state, CLOCK_STATES.get(state, "invalid"), reserved, "none" if error == 0xFFFFFFFF else error)),
            ([h("q", offset)], "clock_offset_ns %d" % offset),
        ]
        for r in self.records:
            sig, role, flags, rate, lost_v, age = r[:6]
            reserved = r[6] if len(r) > 6 else 0
            out += [
                ([h("H", sig), h("B", role), h("B", flags), h("I", rate)],
                 "record: signal %d, role %d (%s), flags %#04x, rate_mhz %d" % (sig, role, ROLES.get(role, "unknown"),
                                                                               flags, rate)),
                ([h("Q", lost_v), h("I", age), h("I", reserved)],
                 "lost %d, age_ms %s, reserved %#x" % (lost_v, "none" if age == 0xFFFFFFFF else age, reserved)),
            ]
        return out


def fmt_value(tname, v):
    if tname == "bool":
        return "true" if v == 1 else "false" if v == 0 else str(v)
    if tname == "uint32" and v > 0xFFFF:
        return "%#x" % v
    return repr(v)


class Frame:
    def __init__(self, name, expect, sender, dest, config_hash, seq, time_ns, flags=0,
                 entries=(), tag=None, note="", summary=None, **bad):
        self.name, self.expect, self.note, self.dest = name, expect, note, dest
        self.summary = summary  # a Summary: the payload instead of entries
        self.sender, self.config_hash, self.seq, self.time_ns = sender, config_hash, seq, time_ns
        self.flags, self.entries, self.tag, self.bad = flags, list(entries), tag, bad

    def lines(self):
        elines = [l for e in self.entries for l in e.lines()] + (self.summary.lines() if self.summary else [])
        payload = sum(len(b"".join(f)) for f, _ in elines)
        head = [h("I", self.bad.get("magic", MAGIC)), h("B", self.bad.get("version", VERSION)),
                h("B", self.flags), h("H", self.sender), h("I", self.config_hash), h("I", self.seq)]
        count = self.bad.get("entry_count", len(self.entries))
        plen = self.bad.get("payload_len", payload)
        out = [
            (head, "magic%s, version %d, flags %#04x, sender %d, config_hash, seq %d"
             % (" (wrong)" if "magic" in self.bad else "", self.bad.get("version", VERSION),
                self.flags, self.sender, self.seq)),
            ([h("Q", self.time_ns), h("H", count), h("H", plen), h("H", self.dest),
              h("H", self.bad.get("reserved", 0))],
             "send_time_ns %d, entry_count %d, payload_len %d, dest %s, reserved %#x"
             % (self.time_ns, count, plen, "all" if self.dest == 0xFFFF else self.dest,
                self.bad.get("reserved", 0))),
        ] + elines
        if self.tag is not None:
            out.append(([self.tag], "authentication tag (opaque to the codec)"))
        if "trailing" in self.bad:
            out.append(([self.bad["trailing"]], "trailing byte(s)"))
        if "truncate" in self.bad:  # keep only the first n bytes, still shown per field
            n, cut = self.bad["truncate"], []
            for fields, comment in out:
                kept = []
                for f in fields:
                    if n <= 0:
                        break
                    kept.append(f[:n])
                    n -= len(f)
                if kept:
                    cut.append((kept, comment + (" (cut)" if n < 0 else "")))
            out = cut
        return out

    def data(self):
        return b"".join(b"".join(f) for f, _ in self.lines())


HASH = 0x1234ABCD
TAG = bytes(range(16))


def vectors():
    dbl = lambda **bad: Entry(3, "double", [3.141592653589793], seq=9, time_ns=1999990000, **bad)
    ev = lambda **bad: Entry(7, "uint32", [17], flags=E_EVENT, seq=5, time_ns=2999999000, **bad)
    i32 = lambda **bad: Entry(1, "int32", [-1, 2, 300000], seq=1, time_ns=4999000000, **bad)
    boo = lambda **bad: Entry(0, "bool", [1], seq=1, time_ns=4999000000, **bad)
    frag = lambda **bad: Fragment(10, "uint32", [398, 399], 400, bad.pop("offset", 1592), seq=11,
                                  time_ns=2000150000, **bad)
    fr = dict(sender=1, dest=2, config_hash=HASH, seq=44, time_ns=2000200000)
    hb = dict(sender=2, dest=0xFFFF, config_hash=HASH, seq=7, time_ns=1000000000, flags=F_HEARTBEAT)
    d = dict(sender=1, dest=2, config_hash=HASH, seq=42, time_ns=2000000500)
    e = dict(sender=3, dest=0, config_hash=HASH, seq=100, time_ns=3000000000)
    s = dict(sender=0, dest=1, config_hash=HASH, seq=1, time_ns=5000000000)
    sm = dict(sender=2, dest=0, config_hash=HASH, seq=3, time_ns=6000000000, flags=F_SUMMARY)
    counters = (12000, 11000, 1, 2, 0)
    recs = [(1, 1, 0x00, 1000000, 0, 1), (4, 2, 0x01, 0, 3, 250)]
    synced = (2, 12500, 1764000000123456789)  # a slave within 12.5 us; realtime - monotonic
    summ = lambda records=recs, clock=synced, **bad: Summary(0, 1, 1000, 5000000000, 0x3, counters, records,
                                                              clock=clock, **bad)
    return [
        # Valid frames (expect=ok). src/wire/wire_test_util.h (ValidVectors) encodes the same contents.
        Frame("heartbeat", "ok", note="(a) heartbeat from node 2 to every node", **hb),
        Frame("double", "ok", entries=[dbl()], note="(b) one `double` state entry, node 1 to node 2", **d),
        Frame("setup", "ok", entries=[
            boo(), i32(),
            Entry(2, "uint32", [0xDEADBEEF], seq=1, time_ns=4999000000),
            Entry(3, "int64", [-5000000000], seq=1, time_ns=4999000000),
            Entry(4, "float", [-1.25], seq=1, time_ns=4999000000),
            Entry(5, "double", [-2.25], seq=1, time_ns=4999000000),
        ], note="(c) set-up-like frame, one entry of each type including an `int32[3]`", **s),
        Frame("event", "ok", entries=[ev()], note="(d) one `uint32` event entry", **e),
        Frame("auth", "ok", sender=1, dest=2, config_hash=HASH, seq=43, time_ns=2000100000, flags=F_AUTH,
              entries=[Entry(9, "int64", [-2], seq=10, time_ns=2000000000)], tag=TAG,
              note="(e) frame with an authentication tag (here 00..0f; the codec does not check it)"),
        Frame("summary", "ok", summary=summ(),
              note="(f) node summary from node 2 to node 0: its clock is synced (error bound 12.5 us), "
                   "it produces signal 1 at 1000 values/s and consumes signal 4, which is stale", **sm),
        Frame("summary-empty-part", "ok", sender=5, dest=0xFFFF, config_hash=HASH, seq=0, time_ns=7000000000,
              flags=F_SUMMARY, summary=Summary(1, 2, 400, 9000000000, 0, (0, 0, 0, 0, 0), []),
              note="(g) part 1 of 2 without records, node 5 to every node"),
        Frame("fragment", "ok", entries=[frag()],
              note="(h) fragment entry: the last part (elements 398 and 399) of a `uint32[400]` state value", **fr),
        # Malformed frames, each one field away from a valid one.
        Frame("short-header", "too_short", truncate=31, note="the heartbeat cut to 31 bytes", **hb),
        Frame("short-payload", "too_short", entries=[dbl()], truncate=56,
              note="`double` without its value bytes", **d),
        Frame("auth-tag-missing", "too_short", sender=2, dest=0xFFFF, config_hash=HASH, seq=8,
              time_ns=1100000000, flags=F_HEARTBEAT | F_AUTH,
              note="flag bit 1 announces a tag that is not there"),
        Frame("bad-magic", "bad_magic", magic=0x43434D58, note="magic \"CCMX\"", **hb),
        Frame("bad-version", "bad_version", version=1, note="version 1 (before the clock in summaries)", **hb),
        Frame("unknown-frame-flag", "bad_header", sender=2, dest=0xFFFF, config_hash=HASH, seq=7,
              time_ns=1000000000, flags=F_HEARTBEAT | 0x08, note="frame flag bit 3 set"),
        Frame("summary-heartbeat", "bad_header", sender=2, dest=0xFFFF, config_hash=HASH, seq=7,
              time_ns=1000000000, flags=F_HEARTBEAT | F_SUMMARY,
              note="flag bits 0 and 2: a heartbeat that claims to be a summary"),
        Frame("header-reserved", "bad_header", reserved=1, note="header reserved field 1", **hb),
        Frame("heartbeat-with-entry", "bad_header", entries=[ev()], sender=3, dest=0, config_hash=HASH,
              seq=100, time_ns=3000000000, flags=F_HEARTBEAT, note="a heartbeat carries no entries"),
        Frame("data-without-entry", "bad_header", note="no heartbeat flag and no entry", **d),
        Frame("frame-too-large", "bad_header", entries=[dbl()], payload_len=1448, truncate=32,
              note="declares 32 + 1448 = 1480 bytes > 1472 (rejected from the header alone)", **d),
        Frame("payload-not-filled", "bad_header", entries=[ev(), ev()], entry_count=1,
              note="entry_count 1 but payload_len covers two entries", **e),
        Frame("entry-past-payload", "bad_entry", entries=[ev()], entry_count=2,
              note="entry_count 2 but payload_len holds one entry", **e),
        Frame("unknown-type", "bad_entry", entries=[ev(type=7)], note="type code 7", **e),
        Frame("count-zero", "bad_entry", entries=[ev(count=0)], note="count 0", **e),
        Frame("value-len-mismatch", "bad_entry", entries=[i32(value_len=8)],
              note="int32 count 3 with value_len 8 (must be 12)", **s),
        Frame("padding-not-zero", "bad_entry", entries=[ev(padding=b"\x00\x00\x00\x01")],
              note="last padding byte 1", **e),
        Frame("bool-two", "bad_entry", entries=[Entry(0, "bool", [2], seq=1, time_ns=4999000000)],
              note="bool value 2", **s),
        Frame("fragment-total-mismatch", "bad_entry", entries=[frag(total=1604)],
              note="fragment whose total_len is not count x element size (400 x 4 = 1600)", **fr),
        Frame("fragment-past-total", "bad_entry", entries=[frag(offset=1596)],
              note="fragment part running past the value's end (1596 + 8 > 1600)", **fr),
        Frame("fragment-misaligned", "bad_entry", entries=[frag(offset=1590)],
              note="fragment offset not a multiple of the element size", **fr),
        Frame("fragment-whole-value", "bad_entry",
              entries=[Fragment(10, "uint32", [398, 399], 2, 0, seq=11, time_ns=2000150000)],
              note="fragment carrying the whole value (a value that fits is sent unfragmented)", **fr),
        Frame("trailing-byte", "trailing_bytes", trailing=b"\x00",
              note="the heartbeat plus one zero byte", **hb),
        Frame("summary-with-entry-count", "bad_header", summary=summ(), entry_count=1,
              note="a summary with entry_count 1 (its body is no entries)", **sm),
        Frame("summary-short-body", "bad_summary", summary=summ(), payload_len=72, truncate=104,
              note="a summary body of 72 bytes, shorter than its 80-byte head (a version-1 head and one record would be 88)", **sm),
        Frame("summary-part-out-of-range", "bad_summary", sender=2, dest=0, config_hash=HASH, seq=3,
              time_ns=6000000000, flags=F_SUMMARY, summary=Summary(1, 1, 1000, 5000000000, 0x3, counters, recs),
              note="part 1 of 1 (parts are numbered from 0)"),
        Frame("summary-count-mismatch", "bad_summary", summary=summ(record_count=3),
              note="record_count 3 but payload_len holds two records", **sm),
        Frame("summary-unknown-role", "bad_summary", summary=summ([(1, 3, 0, 0, 0, 1)]),
              note="record role 3", **sm),
        Frame("summary-record-flag", "bad_summary", summary=summ([(1, 1, 0x04, 0, 0, 1)]),
              note="record flag bit 2 set", **sm),
        Frame("summary-not-increasing", "bad_summary", summary=summ([recs[1], recs[0]]),
              note="records not in increasing signal order (4, then 1)", **sm),
        Frame("summary-clock-state", "bad_summary", summary=summ(clock=(4, 0xFFFFFFFF, 0)),
              note="a summary whose clock_state is 4 (0-3 are defined)", **sm),
        Frame("summary-clock-reserved", "bad_summary", summary=summ(clock_reserved=1),
              note="a summary whose clock reserved byte is not 0", **sm),
        Frame("summary-record-reserved", "bad_summary", summary=summ([(1, 1, 0, 0, 0, 1, 1)]),
              note="record reserved field 1", **sm),
    ]


def fragment_stream(count, values, part=1408, edit=None, periodic=False):
    """fuzz_reassembly input: uint32[count], each value (seq, fill) split as ccommd does."""
    frames = []
    for seq, fill in values:
        for off in range(0, count * 4, part):
            n = min(part, count * 4 - off) // 4
            frames.append(Frame("s", "ok", sender=1, dest=0, config_hash=HASH, seq=len(frames), time_ns=seq,
                                entries=[Fragment(5, "uint32", [fill] * n, count, off, seq=seq, time_ns=seq)]).data())
    if edit:
        frames = edit(frames)
    out = bytes([TYPES["uint32"][0] - 1 + (0x80 if periodic else 0)]) + struct.pack(">H", count - 2)
    return out + b"".join(struct.pack(">H", len(f)) + f for f in frames)


def write_reassembly_corpus(d):
    os.makedirs(d, exist_ok=True)
    seeds = {
        "in-order": fragment_stream(400, [(1, 7), (2, 8)]),
        "small-parts": fragment_stream(16, [(1, 7), (2, 8)], part=16),
        "duplicate": fragment_stream(400, [(1, 7), (2, 8)], edit=lambda f: f[:1] + f[:1] + f[1:]),
        "gap": fragment_stream(1000, [(1, 7), (2, 8)], edit=lambda f: f[:1] + f[2:]),
        "reordered": fragment_stream(1000, [(1, 7), (2, 8)], edit=lambda f: [f[1], f[0]] + f[2:]),
        "periodic-resend": fragment_stream(1000, [(1, 7), (1, 7), (2, 8)], periodic=True,
                                           edit=lambda f: f[:1] + f[2:]),
    }
    for name, data in seeds.items():
        with open(os.path.join(d, name + ".bin"), "wb") as f:
            f.write(data)


def block(v):
    out = [v.note[0].upper() + v.note[1:] + ":"] if v.note else []
    out += ["```hex name=%s expect=%s" % (v.name, v.expect)]
    rows = [(" ".join(f.hex() for f in fields), c) for fields, c in v.lines()]
    width = max(len(r) for r, _ in rows)
    out += ["%-*s  # %s" % (width, r, c) for r, c in rows]
    out.append("```")
    return "\n".join(out)


BLOCK_RE = re.compile(r"^```hex\s+name=(\S+)\s+expect=(\S+)\s*\n(.*?)^```", re.M | re.S)


def parse_doc(text):
    found = {}
    for m in BLOCK_RE.finditer(text):
        hexdigits = "".join(line.split("#", 1)[0] for line in m.group(3).splitlines())
        hexdigits = re.sub(r"\s+", "", hexdigits)
        if m.group(1) in found:
            raise ValueError("vector %s appears twice" % m.group(1))
        found[m.group(1)] = (m.group(2), bytes.fromhex(hexdigits))
    return found


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--doc", default=os.path.join(root, "docs", "protocol.md"))
    ap.add_argument("--emit", action="store_true")
    ap.add_argument("--corpus", metavar="DIR")
    ap.add_argument("--reassembly-corpus", metavar="DIR")
    args = ap.parse_args()
    vs = vectors()
    if args.emit:
        out = []
        for i, v in enumerate(vs):
            if v.expect != "ok" and (i == 0 or vs[i - 1].expect == "ok"):
                out.append("### Malformed frames")
            out.append(block(v))
        print("\n\n".join(out))
        return 0
    if args.reassembly_corpus:
        write_reassembly_corpus(args.reassembly_corpus)
        return 0
    if args.corpus:
        # The vectors, plus inputs the fuzzer would take long to find by itself: the
        # largest frame, and a heartbeat as raw Ethernet delivers it (zero-padded to 46).
        big = Frame("max-frame", "ok", sender=1, dest=0, config_hash=HASH, seq=1, time_ns=1,
                    entries=[Entry(1, "double", [float(i) for i in range(177)])]).data()
        assert len(big) == 1472
        seeds = [(v.name, v.data()) for v in vs]
        full = Frame("max-summary", "ok", sender=1, dest=0xFFFF, config_hash=HASH, seq=1, time_ns=1,
                     flags=F_SUMMARY | F_AUTH, tag=TAG,
                     summary=Summary(0, 2, 1000, 1, 0x7, (1, 2, 3, 4, 5),
                                     [(i, 1 + i % 2, i % 4, i, i, i) for i in range(56)])).data()
        assert len(full) == 32 + 80 + 56 * 24 + 16
        seeds += [("max-frame", big), ("eth-padded-heartbeat", vs[0].data().ljust(46, b"\0")),
                  ("max-summary", full)]
        os.makedirs(args.corpus, exist_ok=True)
        for name, data in seeds:
            with open(os.path.join(args.corpus, name + ".bin"), "wb") as f:
                f.write(data)
        return 0
    with open(args.doc, encoding="utf-8") as f:
        doc = parse_doc(f.read())
    errors = []
    for v in vs:
        if v.name not in doc:
            errors.append("%s: missing from the document" % v.name)
            continue
        expect, data = doc.pop(v.name)
        if expect != v.expect:
            errors.append("%s: document expects %s, script %s" % (v.name, expect, v.expect))
        if data != v.data():
            errors.append("%s: bytes differ\n  doc:    %s\n  script: %s" % (v.name, data.hex(), v.data().hex()))
    errors += ["%s: in the document but not in this script" % n for n in doc]
    for e in errors:
        print("wire_vectors: " + e, file=sys.stderr)
    if not errors:
        print("wire_vectors: %d vectors match %s" % (len(vs), os.path.relpath(args.doc)))
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
