#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The docs say what the code does, where they state a number or a list the code defines.

  check_docs.py SOURCE_DIR

Each fact is read from the code and looked for in the docs that state it:
  - the wire version (src/wire/wire.h kVersion): docs/protocol.md's title and its "the
    version stays N" / "wire version N does not have" lines, README.md's docs table;
  - the production age's error term (src/client/system_view_reader.cpp: N offset
    readings of kOffsetReadingNs each): the error_ns comment in ccomm.h and docs/design.md;
  - what frames_rx counts (the receive path counts node summaries in it): docs/usage.md;
  - every error message of the send cycle, of <clock> and of stale_by (Err(...) in
    src/config/): a row of docs/config.md's error table.
Exit 0 if all hold, 1 with one line per disagreement.
"""
import glob
import os
import re
import sys


def read(root, path):
    with open(os.path.join(root, path), encoding="utf-8") as f:
        return f.read()


def wire_version(root, bad):
    m = re.search(r"constexpr uint8_t kVersion = (\d+);", read(root, "src/wire/wire.h"))
    version = m.group(1)
    protocol = read(root, "docs/protocol.md")
    title = re.search(r"^# ccomm wire protocol, version (\d+)", protocol, re.M)
    if not title or title.group(1) != version:
        bad.append("docs/protocol.md: title says version %s, wire.h kVersion is %s" % (title and title.group(1), version))
    # Present-tense statements of the version (history keeps its own numbers).
    for n, line in enumerate(protocol.splitlines(), 1):
        for pat in (r"the version stays (\d+)", r"wire version (\d+) does not have"):
            for v in re.findall(pat, line):
                if v != version:
                    bad.append("docs/protocol.md:%d: '%s' (the wire version is %s)" % (n, line.strip(), version))
    readme = read(root, "README.md")
    for n, line in enumerate(readme.splitlines(), 1):
        for v in re.findall(r"wire format v(\d+)", line):
            if v != version:
                bad.append("README.md:%d: says wire format v%s, wire.h kVersion is %s" % (n, v, version))


def production_age_error(root, bad):
    src = read(root, "src/client/system_view_reader.cpp")
    per = int(re.search(r"kOffsetReadingNs = (\d+);", src).group(1))
    times = re.search(r"error_ns\)\s*\+\s*(\d+)\s*\*\s*kOffsetReadingNs", src)
    total_us = per * (int(times.group(1)) if times else 1) / 1000
    total = "%g us" % total_us
    header = read(root, "src/include/ccomm/ccomm.h")
    m = re.search(r"int64_t error_ns;\s*/\*\*<(.*?)\*/", header, re.S)
    said = re.findall(r"plus (\d+) us", m.group(1)) if m else []
    if said != ["%g" % total_us]:
        bad.append("ccomm.h: error_ns says plus %s us for reading the clocks' offsets; the code adds %s"
                   % ("/".join(said) or "nothing", total))
    design = read(root, "docs/design.md")
    said = re.findall(r"plus (\d+) us for reading the offsets", design)
    if said != ["%g" % total_us]:
        bad.append("docs/design.md: production age error plus %s us; the code adds %s" % ("/".join(said) or "?", total))


def frames_rx(root, bad):
    src = read(root, "src/daemon/engine/receive_path.cpp")
    summary = src[src.index("void ReceivePath::HandleSummary"):]
    summary = summary[:summary.index("\n}\n")]
    if "kFramesRx" not in summary:
        return
    row = re.search(r"^\| `frames_rx` \|([^\n]*)", read(root, "docs/usage.md"), re.M)
    if not row or "summar" not in row.group(1):
        bad.append("docs/usage.md: the frames_rx row leaves out node summaries, which the receive path counts in it")


TOPICS = re.compile(r"send_cycle|send_phase|send_lead|launch_time|<clock>|grandmaster|timestamping|stale_by|"
                    r"socket ")


def error_table(root, bad):
    doc = read(root, "docs/config.md")
    table = doc[doc.index("### Error messages"):doc.index("## XML Schema")]
    table = table.replace("\\|", "|")
    for path in sorted(glob.glob(os.path.join(root, "src/config/*.cpp"))):
        if path.endswith("_test.cpp") or "fuzz" in path:
            continue
        src = open(path, encoding="utf-8").read()
        whole_file = path.endswith("clock_section.cpp")
        for m in re.finditer(r"\bErr\(", src):
            call = src[m.end():src.index(");", m.end())]
            literals = [s.replace('\\"', '"') for s in re.findall(r'"((?:[^"\\]|\\.)*)"', call)]
            text = "".join(literals)
            if not whole_file and not TOPICS.search(text + call):
                continue
            line = src[:m.start()].count("\n") + 1
            # Each fixed part of the message, up to an explanation in parentheses.
            for part in literals:
                part = part.split(" (")[0].strip(" :")
                if len(part) >= 8 and not part.startswith("(") and part not in table:
                    bad.append("docs/config.md error table: no row has '%s' (%s:%d)"
                               % (part, os.path.relpath(path, root), line))


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
    bad = []
    for check in (wire_version, production_age_error, frames_rx, error_table):
        check(root, bad)
    for b in bad:
        print("docs: " + b)
    print("docs: %d disagreements with the code" % len(bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
