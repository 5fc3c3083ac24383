#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""docs/signals.xsd accepts every file ccommd accepts.

  schema_accepts_test.py CCOMMD[,SECTION_CHECKER...] XSD FILE_OR_DIR...

Each XML file given (directories: their *.xml and every file of fuzz corpora) that
`ccommd --check` accepts, and every checker of an extension section (`CHECKER FILE`, e.g.
the bridge's <ros2> checker: ccommd checks only the structure of such a section) with
it, must also validate under xmllint, and variants of each with its
empty elements written with an end tag and whitespace between (<x ...>\\n  </x>) too.
The parser stays the authority; the schema must never refuse what it accepts.
And on the edges of the address ranges (a node's multicast=, the network's multicast_base=)
both must agree: each value either both accept or both refuse (BOUNDARIES below).
Exit 0 if all hold, 1 with one line per file the schema refuses.
"""
import os
import re
import subprocess
import sys
import tempfile


def files(paths):
    for p in paths:
        if os.path.isdir(p):
            for f in sorted(os.listdir(p)):
                yield os.path.join(p, f)
        else:
            yield p


def accepted(checkers, path):
    ccommd, sections = checkers[0], checkers[1:]
    run = lambda argv: subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0
    return run([ccommd, "--check", path]) and all(run([c, path]) for c in sections)


def validates(xsd, path):
    cp = subprocess.run(["xmllint", "--noout", "--schema", xsd, path], stdout=subprocess.DEVNULL,
                        stderr=subprocess.PIPE, text=True)
    return cp.returncode == 0, cp.stderr.strip().splitlines()[:2]


# A minimal two-node UDP file; {network} and {node} are attributes under test.
TEMPLATE = """<?xml version="1.0" encoding="UTF-8"?>
<ccomm version="1">
  <network {network}/>
  <node name="a" ip="127.0.0.1" transport="udp" {node}/>
  <node name="b" ip="127.0.0.2" transport="udp"/>
  <signal name="s" type="double" producer="a" consumers="b"/>
</ccomm>
"""
# (attribute, where, values): the ends of 224.0.0.0/4 and, for multicast_base, of its last
# byte (at most 191: 64 node groups and the summary group); a node's group has no such limit.
BOUNDARIES = [
    ("multicast", "node", ["224.0.0.0", "239.255.255.255", "239.255.255.191", "239.255.255.192", "239.1.2.250",
                           "223.255.255.255", "240.0.0.0", "239.255.255.256"]),
    ("multicast_base", "network", ["224.0.0.0", "239.255.67.0", "239.255.255.191", "239.255.255.192",
                                   "239.255.255.255", "223.255.255.0", "240.0.0.0"]),
]


def boundaries(ccommd, xsd, tmp):
    """Lines for each value where ccommd --check and the schema disagree."""
    bad = []
    for attr, where, values in BOUNDARIES:
        for value in values:
            extra = 'fanout="multicast" ' if attr == "multicast_base" else ""
            text = TEMPLATE.format(network=extra + (f'{attr}="{value}"' if where == "network" else ""),
                                   node=f'{attr}="{value}"' if where == "node" else "")
            path = os.path.join(tmp, "boundary.xml")
            open(path, "w", encoding="utf-8").write(text)
            by_parser, (by_schema, why) = accepted(ccommd[:1], path), validates(xsd, path)
            if by_parser != by_schema:
                bad.append("<%s %s=\"%s\">: ccommd --check %s it, the schema %s it%s" % (
                    where, attr, value, "accepts" if by_parser else "refuses",
                    "accepts" if by_schema else "refuses", (": " + " / ".join(why)) if why else ""))
    return bad


def main():
    ccommd, xsd, paths = sys.argv[1].split(","), sys.argv[2], sys.argv[3:]
    bad, checked = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for path in files(paths):
            if not os.path.isfile(path) or not accepted(ccommd, path):
                continue
            text = open(path, encoding="utf-8", errors="replace").read()
            # The same file with every self-closing element opened and closed explicitly.
            spread = re.sub(r"<(\w+)([^<>]*?)\s*/>", r"<\1\2>\n  </\1>", text)
            variant = os.path.join(tmp, "spread.xml")
            open(variant, "w", encoding="utf-8").write(spread)
            for name, candidate in ((path, path), (path + " (end tags, whitespace)", variant)):
                if candidate == variant and not accepted(ccommd, variant):
                    continue
                checked += 1
                ok, why = validates(xsd, candidate)
                if not ok:
                    bad.append("%s: ccommd (and the section checkers) accept it, the schema refuses it: %s" % (name, " / ".join(why)))
        bad += boundaries(ccommd, xsd, tmp)
    for b in bad:
        print("schema: " + b)
    print("schema: %d accepted files checked, %d refused by the schema" % (checked, len(bad)))
    return 1 if bad or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
