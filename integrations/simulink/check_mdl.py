#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Checks the ccomm Simulink block library (a text .mdl file) without MATLAB.

Parses the .mdl structure (sections `Name { ... }`, `Key value` lines whose value is a
quoted string, possibly continued by further quoted strings on the next lines, a number,
an [array] or a bare word; `#` comments) and checks what Simulink needs from the ccomm
blocks: balanced sections, one Library with a System, and for every S-Function block
the S-function name, a mask whose variables are exactly the S-function's parameters in
the order the C code reads them (P_* in sfun_ccomm_common.h), each named (signal, ts,
width, node, dtype, timeout, status), with as many prompts, styles and values as
variables, a data type popup offering exactly the types the blocks accept, and Ports
matching the default status output.

  check_mdl.py [LIBRARY.mdl] [--common sfun_ccomm_common.h]
  check_mdl.py --fuzz N [--seed S]   # N mutated copies: each must parse or be refused
                                     # with FILE:LINE, never crash the checker

Exit 0 if the library is valid; 1 with FILE:LINE: reason for each problem.
"""
from __future__ import annotations

import argparse
import random
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
NAMES = ["signal", "ts", "width", "node", "dtype", "timeout", "status"]
REQUIRED = {"signal", "node", "timeout", "status"}
DTYPES = ["double", "single", "int32", "uint32", "boolean"]
SFUNCTIONS = {"sfun_ccomm_read": [0, 2], "sfun_ccomm_write": [1, 1]}  # Ports with status on
STYLES = re.compile(r"edit|checkbox|popup\([^()]*\)")


class MdlError(Exception):
    pass


@dataclass
class Section:
    name: str
    line: int
    params: dict = field(default_factory=dict)   # key -> (value, line)
    children: list = field(default_factory=list)


TOKEN = re.compile(r'''
    (?P<ws>[ \t\r]+) | (?P<nl>\n) | (?P<comment>\#[^\n]*) |
    (?P<string>"(?:[^"\\\n]|\\.)*") | (?P<open>\{) | (?P<close>\}) |
    (?P<array>\[[^\[\]\n]*\]) | (?P<word>[A-Za-z_$][A-Za-z0-9_.$-]*) |
    (?P<number>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)
''', re.X)


def unescape(s: str) -> str:
    return re.sub(r"\\(.)", lambda m: {"n": "\n", "t": "\t"}.get(m.group(1), m.group(1)), s[1:-1])


def tokens(text: str, path: str):
    pos, line = 0, 1
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m:
            raise MdlError(f"{path}:{line}: unexpected character {text[pos]!r}")
        kind = m.lastgroup
        if kind == "nl":
            yield ("nl", "\n", line)
            line += 1
        elif kind == "string" or kind not in ("ws", "comment"):
            yield (kind, m.group(), line)
        pos = m.end()
    yield ("nl", "\n", line)


def parse(text: str, path: str) -> list[Section]:
    """Returns the top-level sections."""
    top: list[Section] = []
    stack: list[Section] = []
    toks = list(tokens(text, path))
    toks += [("eof", "end of file", toks[-1][2])] * 3  # lookahead never runs off the end
    i = 0
    while toks[i][0] != "eof":
        kind, val, line = toks[i]
        if kind == "nl":
            i += 1
            continue
        if kind == "close":
            if not stack:
                raise MdlError(f"{path}:{line}: '}}' without an open section")
            stack.pop()
            i += 1
            continue
        if kind != "word":
            raise MdlError(f"{path}:{line}: expected a parameter or section name, got {val!r}")
        nkind, nval, _ = toks[i + 1]
        if nkind == "open":
            sec = Section(val, line)
            (stack[-1].children if stack else top).append(sec)
            stack.append(sec)
            i += 2
            continue
        if not stack:
            raise MdlError(f"{path}:{line}: parameter {val} outside any section")
        if nkind == "string":
            parts, j = [], i + 1
            while toks[j][0] == "string":  # a long string continues on the next lines
                parts.append(unescape(toks[j][1]))
                j += 1
                if toks[j][0] == "nl" and toks[j + 1][0] == "string":
                    j += 1
            value = "".join(parts)
        elif nkind in ("number", "word", "array"):
            value, j = nval, i + 2
        else:
            raise MdlError(f"{path}:{line}: parameter {val} has no value")
        if toks[j][0] not in ("nl", "close"):
            raise MdlError(f"{path}:{line}: unexpected {toks[j][1]!r} after parameter {val}")
        if val in stack[-1].params:
            raise MdlError(f"{path}:{line}: {stack[-1].name} sets {val} twice "
                           f"(first on line {stack[-1].params[val][1]})")
        stack[-1].params[val] = (value, line)
        i = j
    if stack:
        raise MdlError(f"{path}: section {stack[-1].name} opened on line {stack[-1].line} is never closed")
    return top


def param_order(common: Path) -> list[str]:
    """The S-function parameter order of the C code: P_NAME 0, P_TS 1, ..."""
    order = {}
    for m in re.finditer(r"#define P_([A-Z]+) (\d+)", common.read_text(encoding="utf-8")):
        order[int(m.group(2))] = m.group(1)
    c_names = {"NAME": "signal", "TS": "ts", "WIDTH": "width", "NODE": "node", "DTYPE": "dtype",
               "TIMEOUT": "timeout", "STATUS": "status"}
    return [c_names.get(order[k], order[k].lower()) for k in sorted(order)]


def check_block(b: Section, path: str, order: list[str]) -> list[str]:
    errs: list[str] = []
    p = b.params

    def get(key: str) -> str | None:
        if key not in p:
            errs.append(f"{path}:{b.line}: block {p.get('Name', ('?',))[0]!r} has no {key}")
            return None
        return p[key][0]

    def at(key: str) -> int:
        return p[key][1] if key in p else b.line

    name, btype = get("Name"), get("BlockType")
    if btype != "S-Function":
        return errs
    fn = get("FunctionName")
    if fn is not None and fn not in SFUNCTIONS:
        errs.append(f"{path}:{at('FunctionName')}: block {name!r}: unknown S-function {fn!r}")
    params = get("Parameters")
    variables = get("MaskVariables")
    if params is None or variables is None:
        return errs
    plist = [s.strip() for s in params.split(",")]
    entries = [e for e in variables.split(";") if e]
    vnames, refs = [], []
    for e in entries:
        m = re.fullmatch(r"([A-Za-z]\w*)=([@&])(\d+)", e)
        if not m:
            errs.append(f"{path}:{at('MaskVariables')}: block {name!r}: bad mask variable {e!r} (want name=@N or name=&N)")
            return errs
        vnames.append(m.group(1))
        refs.append(int(m.group(3)))
    if refs != list(range(1, len(refs) + 1)):
        errs.append(f"{path}:{at('MaskVariables')}: block {name!r}: mask variables numbered {refs}, want 1..{len(refs)}")
    if plist != vnames:
        errs.append(f"{path}:{at('Parameters')}: block {name!r}: Parameters {plist} differ from the mask variables {vnames}")
    if plist != order:
        errs.append(f"{path}:{at('Parameters')}: block {name!r}: Parameters {plist}, but the S-function reads {order}")
    missing = REQUIRED - set(plist)
    if missing:
        errs.append(f"{path}:{at('Parameters')}: block {name!r}: no parameter named {', '.join(sorted(missing))}")
    for key, n in (("MaskPromptString", "|"), ("MaskValueString", "|"), ("MaskTunableValueString", ","),
                   ("MaskEnableString", ","), ("MaskVisibilityString", ",")):
        v = get(key)
        if v is not None and len(v.split(n)) != len(vnames):
            errs.append(f"{path}:{at(key)}: block {name!r}: {key} has {len(v.split(n))} entries for {len(vnames)} variables")
    style = get("MaskStyleString")
    if style is not None:
        styles = STYLES.findall(style)
        if ",".join(styles) != style or len(styles) != len(vnames):
            errs.append(f"{path}:{at('MaskStyleString')}: block {name!r}: MaskStyleString {style!r} is not "
                        f"{len(vnames)} of edit, checkbox, popup(...)")
        elif "dtype" in vnames:
            dstyle = styles[vnames.index("dtype")]
            if dstyle != f"popup({'|'.join(DTYPES)})":
                errs.append(f"{path}:{at('MaskStyleString')}: block {name!r}: data type popup {dstyle!r}, "
                            f"want popup({'|'.join(DTYPES)})")
            elif refs and entries[vnames.index("dtype")].split("=")[1][0] != "&":
                errs.append(f"{path}:{at('MaskVariables')}: block {name!r}: dtype must be passed as text (&N)")
        values = p.get("MaskValueString", ("",))[0].split("|")
        if "dtype" in vnames and len(values) == len(vnames) and values[vnames.index("dtype")] not in DTYPES:
            errs.append(f"{path}:{at('MaskValueString')}: block {name!r}: default data type "
                        f"{values[vnames.index('dtype')]!r} is not one of {DTYPES}")
    ports = get("Ports")
    if ports is not None and fn in SFUNCTIONS:
        got = [int(x) for x in re.findall(r"-?\d+", ports)]
        if got != SFUNCTIONS[fn]:
            errs.append(f"{path}:{at('Ports')}: block {name!r}: Ports {ports}, the S-function has {SFUNCTIONS[fn]}")
    return errs


def check(path: Path, common: Path) -> tuple[list[str], str]:
    text = path.read_text(encoding="utf-8", errors="replace")
    try:
        top = parse(text, str(path))
    except MdlError as e:
        return [str(e)], ""
    libs = [s for s in top if s.name == "Library"]
    if len(top) != 1 or not libs:
        return [f"{path}:1: expected exactly one top-level Library section, found "
                f"{', '.join(s.name for s in top) or 'none'}"], ""
    lib = libs[0]
    errs = []
    if "Name" not in lib.params:
        errs.append(f"{path}:{lib.line}: Library has no Name")
    systems = [c for c in lib.children if c.name == "System"]
    if len(systems) != 1:
        return errs + [f"{path}:{lib.line}: Library has {len(systems)} System sections, want 1"], ""
    order = param_order(common)
    blocks = [c for c in systems[0].children if c.name == "Block"]
    seen: dict[str, int] = {}
    for b in blocks:
        n = b.params.get("Name", ("",))[0]
        if n in seen:
            errs.append(f"{path}:{b.line}: block name {n!r} used twice (line {seen[n]})")
        seen[n] = b.line
        errs += check_block(b, str(path), order)
    fns = sorted(b.params.get("FunctionName", ("",))[0] for b in blocks)
    if fns != sorted(SFUNCTIONS):
        errs.append(f"{path}:{systems[0].line}: the library's S-function blocks are {fns}, want {sorted(SFUNCTIONS)}")
    summary = f"{path.name}: Library {lib.params.get('Name', ('?',))[0]!r}, " + ", ".join(
        f"{b.params['Name'][0]!r} ({b.params.get('FunctionName', ('?',))[0]}, "
        f"{len(b.params.get('Parameters', ('',))[0].split(','))} named parameters)" for b in blocks if "Name" in b.params)
    return errs, summary


def fuzz(path: Path, common: Path, n: int, seed: int, work: Path) -> int:
    rnd = random.Random(seed)
    data = path.read_bytes()
    refused = 0
    for k in range(n):
        b = bytearray(data)
        for _ in range(rnd.randint(1, 4)):
            op, at = rnd.randrange(4), rnd.randrange(len(b) or 1)
            if op == 0 and b:
                del b[at:at + rnd.randint(1, 40)]
            elif op == 1:
                b[at:at] = bytes(rnd.choice(b'{}[]"\\\n#;=|,&@ abcXYZ019') for _ in range(rnd.randint(1, 6)))
            elif op == 2:
                b = b[:at]
            else:
                j = rnd.randrange(len(b) or 1)
                b[at:at] = b[j:j + rnd.randint(1, 80)]
        f = work / f"fuzz_{k}.mdl"
        f.write_bytes(bytes(b))
        try:
            errs, _ = check(f, common)
        except Exception as e:  # the point of fuzzing: the checker itself must not crash
            print(f"FAIL fuzz case {k} (seed {seed}): checker crashed: {type(e).__name__}: {e}")
            return 1
        if errs:
            refused += 1
            if not re.match(rf"{re.escape(str(f))}(:\d+)?: ", errs[0]):
                print(f"FAIL fuzz case {k}: error without FILE:LINE: {errs[0]}")
                return 1
        f.unlink()
    print(f"PASS fuzz: {n} mutated libraries, {refused} refused with FILE:LINE, {n - refused} valid, no crash")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("library", nargs="?", type=Path, default=HERE / "ccomm_lib.mdl")
    ap.add_argument("--common", type=Path, default=HERE / "sfun_ccomm_common.h",
                    help="the S-functions' parameter definitions (P_*)")
    ap.add_argument("--fuzz", type=int, metavar="N", help="check N mutated copies instead")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--work", type=Path, default=Path("."), help="directory for fuzz cases")
    a = ap.parse_args()
    try:
        if a.fuzz:
            return fuzz(a.library, a.common, a.fuzz, a.seed, a.work)
        errs, summary = check(a.library, a.common)
    except OSError as e:
        print(f"check_mdl: {e}", file=sys.stderr)
        return 1
    for e in errs:
        print(e)
    if errs:
        return 1
    print(f"PASS {summary}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
