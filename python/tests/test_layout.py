# SPDX-License-Identifier: Apache-2.0
"""The Python binding against ccomm.h and libccomm: a struct layout that differs from the
header fails here, and so does a buffer the library writes past.

1. test_struct_layouts compiles a C program that prints sizeof and offsetof of every field
   of every public struct of ccomm.h, as the ctypes structures of ccomm._native name them,
   and compares: a field added, removed, moved or resized in the header (a struct that
   grew from 88 to 104 bytes) fails, and so does a public struct the binding lacks.
2. test_no_call_writes_past_its_struct places each struct at the very end of a page
   followed by an inaccessible one (a guard page) and makes every call that fills one:
   a library writing more than the binding allocated crashes the child process, and the
   test says which call.
"""
from __future__ import annotations

import ctypes
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Dict, List, Tuple

import pytest

from ccomm import _native

HERE = Path(__file__).resolve().parent
HEADER = HERE.parent.parent / "src" / "include" / "ccomm" / "ccomm.h"


def header_structs() -> List[str]:
    """Every `typedef struct NAME {` of ccomm.h: the public structs with a layout."""
    return re.findall(r"typedef struct (\w+) \{", HEADER.read_text())


def c_layouts(tmp: Path) -> Dict[str, Tuple[int, Dict[str, Tuple[int, int]]]]:
    """{struct: (sizeof, {field: (offsetof, sizeof)})} as the C compiler lays ccomm.h out,
    for the fields the ctypes structures name."""
    lines = ["#include <stddef.h>", "#include <stdio.h>", '#include "ccomm/ccomm.h"', "int main(void) {"]
    for cname, cls in _native.STRUCTS.items():
        lines.append(f'  printf("{cname} - %zu %zu\\n", (size_t)0, sizeof({cname}));')
        for field, _t in cls._fields_:
            lines.append(f'  printf("{cname} {field} %zu %zu\\n", offsetof({cname}, {field}), '
                         f'sizeof((({cname}*)0)->{field}));')
    lines += ["  return 0;", "}"]
    src, exe = tmp / "layout.c", tmp / "layout"
    src.write_text("\n".join(lines) + "\n")
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler (cc) to lay out ccomm.h")
    built = subprocess.run([cc, "-std=c11", "-Wall", "-Werror", "-I", str(HEADER.parent.parent),
                            str(src), "-o", str(exe)], capture_output=True, text=True)
    assert built.returncode == 0, f"ccomm.h lacks a field the Python binding names:\n{built.stderr}"
    out: Dict[str, Tuple[int, Dict[str, Tuple[int, int]]]] = {}
    for line in subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.splitlines():
        cname, field, a, b = line.split()
        if field == "-":
            out[cname] = (int(b), {})
        else:
            out[cname][1][field] = (int(a), int(b))
    return out


def test_type_names_and_sizes_are_the_librarys() -> None:
    """SignalType mirrors ccomm_type: its names and element sizes are ccomm_type_name()'s
    and ccomm_type_size()'s, the one table (common/value_type.h)."""
    from ccomm.client import _DTYPES, SignalType
    L = _native.lib()
    for t in SignalType:
        assert L.ccomm_type_name(int(t)).decode() == t.type_name
        assert L.ccomm_type_size(int(t)) == _DTYPES[t].itemsize
        assert L.ccomm_type_from_name(t.type_name.encode()) == int(t)
    assert L.ccomm_type_name(0) is None and L.ccomm_type_name(len(SignalType) + 1) is None
    assert L.ccomm_type_size(99) == 0 and L.ccomm_type_from_name(b"single") == -1


def test_every_public_struct_is_bound() -> None:
    assert HEADER.is_file(), HEADER
    missing = sorted(set(header_structs()) - set(_native.STRUCTS))
    assert not missing, f"ccomm.h structs without a ctypes structure in ccomm._native: {missing}"


def test_struct_layouts(tmp_path: Path) -> None:
    c = c_layouts(tmp_path)
    wrong = []
    for cname, cls in _native.STRUCTS.items():
        size, fields = c[cname]
        if ctypes.sizeof(cls) != size:
            wrong.append(f"{cname}: sizeof {size} in ccomm.h, {ctypes.sizeof(cls)} in ccomm._native.{cls.__name__}")
        for field, _t in cls._fields_:
            desc = getattr(cls, field)
            if (desc.offset, desc.size) != fields[field]:
                wrong.append(f"{cname}.{field}: offset/size {fields[field]} in ccomm.h, "
                             f"({desc.offset}, {desc.size}) in ccomm._native.{cls.__name__}")
    assert not wrong, "the Python binding differs from ccomm.h:\n" + "\n".join(wrong)


# The child: makes one call with its struct at the end of a page, the next page PROT_NONE.
# argv: struct name, bytes before the guard page (default: the ctypes structure's size),
# size passed to a *_sized call (default: those bytes).
GUARDED_CALL = r'''
import ctypes, mmap, sys
from ccomm import _native
name = sys.argv[1]
room = int(sys.argv[2]) if len(sys.argv) > 2 else ctypes.sizeof(_native.STRUCTS[name])
size = int(sys.argv[3]) if len(sys.argv) > 3 else room
L = _native.lib()
libc = ctypes.CDLL(None, use_errno=True)
libc.mprotect.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
page = mmap.PAGESIZE
m = mmap.mmap(-1, 2 * page)
base = ctypes.addressof(ctypes.c_char.from_buffer(m))
assert libc.mprotect(base + page, page, 0) == 0  # PROT_NONE
p = base + page - room
h = ctypes.c_void_p()
assert L.ccomm_open(b"pytest", 0, ctypes.byref(h)) == 0
h = h.value
d = L.ccomm_find(h, b"d")
remote = L.ccomm_find(h, b"remote_x")
val = (ctypes.c_ubyte * 8)()
if name == "ccomm_info":
    r = L.ccomm_read(h, d, val, 8, p)
elif name == "ccomm_signal_desc":
    r = L.ccomm_describe_sized(h, d, p, size)
elif name == "ccomm_history_cursor":
    r = L.ccomm_history_start(h, remote, 1, p)
elif name == "ccomm_history_info":
    cur = _native.HistoryCursor()
    assert L.ccomm_history_start(h, remote, 1, ctypes.byref(cur)) == 0
    r = L.ccomm_history_read(h, remote, ctypes.byref(cur), val, 8, p)
elif name == "ccomm_signal_stats":
    r = L.ccomm_get_signal_stats_sized(h, d, p, size)
elif name == "plain ccomm_get_signal_stats":  # the symbol programs built against 0.1.0 call
    L.ccomm_get_signal_stats.argtypes = [ctypes.c_void_p, ctypes.c_int32, ctypes.c_void_p]
    r = L.ccomm_get_signal_stats(h, d, p)
elif name == "ccomm_peer_stats":
    r = L.ccomm_get_peer_stats_sized(h, 0, p, size)
elif name == "ccomm_peer_clock":
    r = L.ccomm_get_peer_clock_sized(h, 0, p, size)
elif name == "ccomm_clock_state":
    r = L.ccomm_get_clock_state_sized(h, p, size)
else:
    v = ctypes.c_void_p()
    assert L.ccomm_view_open(h, ctypes.byref(v)) == 0
    if name == "ccomm_view_node":
        r = L.ccomm_view_get_node_sized(v, 0, p, size)
    elif name == "ccomm_view_signal":
        r = L.ccomm_view_get_signal_sized(v, 0, d, p, size)
    elif name == "ccomm_production_age":
        info = _native.Info()
        assert L.ccomm_read(h, d, val, 8, ctypes.byref(info)) >= 0
        r = L.ccomm_view_production_age_sized(v, d, ctypes.byref(info), p, size)
    else:
        r = L.ccomm_view_get_counters_sized(v, p, size)
print("result", r)
'''


def guarded_call(struct: str, *room_size: int) -> "subprocess.CompletedProcess[str]":
    args = [sys.executable, "-c", GUARDED_CALL, struct] + [str(n) for n in room_size]
    return subprocess.run(args, capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("struct", sorted(_native.STRUCTS))
def test_no_call_writes_past_its_struct(node: str, struct: str) -> None:
    r = guarded_call(struct)
    assert r.returncode == 0, (f"the call filling {struct} wrote past the {ctypes.sizeof(_native.STRUCTS[struct])} "
                               f"bytes the binding gives it (exit {r.returncode}): {r.stderr[-2000:]}")
    assert r.stdout.startswith("result "), r.stdout


def test_guard_page_catches_a_short_buffer(node: str) -> None:
    """The check above can fail: 88 bytes (what the replay's own binding once gave the
    104-byte ccomm_signal_stats) with the library told 104 crashes the child."""
    r = guarded_call("ccomm_signal_stats", 88, 104)
    assert r.returncode != 0, r.stdout


def test_sized_calls_take_the_callers_size(node: str) -> None:
    """ccomm.h "Growable structs": a caller's struct larger than the library's gets zeros
    beyond, one smaller than the first layout is refused, untouched; the plain symbol
    fills the 0.1.0 layout (80 bytes) for programs built against that header."""
    L, d = _native.lib(), None
    h = ctypes.c_void_p()
    assert L.ccomm_open(node.encode(), 0, ctypes.byref(h)) == 0
    try:
        d = L.ccomm_find(h, b"d")
        big = (ctypes.c_ubyte * 120)(*([0xFF] * 120))
        assert L.ccomm_get_signal_stats_sized(h, d, big, 120) == 0
        assert bytes(big[104:]) == bytes(16)  # a newer caller's fields: zero
        assert bytes(big[88:96]) == bytes(8)  # fragments_refused of a fresh signal: 0
        small = (ctypes.c_ubyte * 88)(*([0xFF] * 88))
        assert L.ccomm_get_signal_stats_sized(h, d, small, 88) == -1  # CCOMM_E_INVAL
        assert bytes(small) == b"\xff" * 88
    finally:
        L.ccomm_close(h)
    r = guarded_call("plain ccomm_get_signal_stats", 80)
    assert r.returncode == 0 and r.stdout.startswith("result 0"), (r.returncode, r.stdout, r.stderr[-2000:])
