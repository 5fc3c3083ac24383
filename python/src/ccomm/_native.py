# SPDX-License-Identifier: Apache-2.0
"""Finds and loads libccomm.so and declares the C API for ctypes."""
from __future__ import annotations

import ctypes
import ctypes.util
import os
from pathlib import Path
from typing import Mapping, Optional, Sequence

# Windows: ccomm.dll in bin/ of a build or of the zip (docs/install.md "Windows").
LIB_NAMES = ("ccomm.dll",) if os.name == "nt" else ("libccomm.so.0", "libccomm.so")
LIB_SUBDIR = "bin" if os.name == "nt" else "lib"


class LibraryNotFoundError(OSError):
    """libccomm.so was not found; the message lists where it was looked for."""


class Info(ctypes.Structure):
    _fields_ = [
        ("status", ctypes.c_int32),
        ("flags", ctypes.c_uint32),
        ("seq", ctypes.c_uint64),
        ("age_ns", ctypes.c_int64),
        ("source_time_ns", ctypes.c_uint64),
        ("lost", ctypes.c_uint64),
    ]


class HistoryCursor(ctypes.Structure):  # ccomm_history_cursor
    _fields_ = [("next", ctypes.c_uint64), ("overrun", ctypes.c_uint64),
                ("internal", ctypes.c_uint64 * 3)]


class HistoryInfo(ctypes.Structure):  # ccomm_history_info
    _fields_ = [("seq", ctypes.c_uint64), ("source_time_ns", ctypes.c_uint64),
                ("receive_time_ns", ctypes.c_uint64), ("overrun", ctypes.c_uint64),
                ("lost", ctypes.c_uint64)]


class SignalDesc(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("type", ctypes.c_int32),
        ("count", ctypes.c_uint32),
        ("value_bytes", ctypes.c_uint32),
        ("is_event", ctypes.c_int32),
        ("produced_here", ctypes.c_int32),
        ("stale_after_ms", ctypes.c_uint32),
        ("producer", ctypes.c_char_p),
        ("consumed_here", ctypes.c_int32),
    ]


class ViewNode(ctypes.Structure):
    """ccomm_view_node (ccomm.h, system view)."""
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("is_self", ctypes.c_int32),
        ("reported", ctypes.c_int32),
        ("alive", ctypes.c_int32),
        ("age_ns", ctypes.c_int64),
        ("timeout_ns", ctypes.c_int64),
        ("uptime_ns", ctypes.c_uint64),
        ("peers_alive", ctypes.c_uint64),
        ("frames_rx", ctypes.c_uint64),
        ("frames_tx", ctypes.c_uint64),
        ("frames_bad", ctypes.c_uint64),
        ("frames_lost", ctypes.c_uint64),
        ("socket_drops", ctypes.c_uint64),
        ("cycle_ms", ctypes.c_uint32),
        ("summaries", ctypes.c_uint64),
    ]


class ViewSignal(ctypes.Structure):
    """ccomm_view_signal."""
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("role", ctypes.c_int32),
        ("stale", ctypes.c_int32),
        ("rate", ctypes.c_double),
        ("lost", ctypes.c_uint64),
        ("age_ns", ctypes.c_int64),
    ]


class ViewCounters(ctypes.Structure):
    """ccomm_view_counters."""
    _fields_ = [
        ("summaries_tx", ctypes.c_uint64),
        ("summaries_rx", ctypes.c_uint64),
        ("summaries_refused", ctypes.c_uint64),
        ("summaries_old", ctypes.c_uint64),
        ("summaries_send_errors", ctypes.c_uint64),
        ("summary_ms", ctypes.c_uint32),
    ]


def _repo_roots(starts: Sequence[Path]) -> list[Path]:
    """Directories above `starts` that look like a ccomm source tree."""
    roots: list[Path] = []
    for start in starts:
        for d in [start, *start.parents]:
            if (d / "src" / "include" / "ccomm" / "ccomm.h").is_file() and d not in roots:
                roots.append(d)
                break
    return roots


# Where a binary wheel carries its libccomm (scripts/package puts it there).
BUNDLED = Path(__file__).resolve().parent / "_lib" / LIB_NAMES[0]


def candidates(env: Mapping[str, str], starts: Sequence[Path],
               bundled: Optional[Path] = None) -> list[Path]:
    """Library paths to try, in order: $CCOMM_LIBRARY, the library bundled in the wheel,
    $CCOMM_BUILD_DIR/lib, the newest build*/lib of an enclosing source tree. (The system
    search comes after these.)"""
    out: list[Path] = []
    if env.get("CCOMM_LIBRARY"):
        return [Path(env["CCOMM_LIBRARY"])]
    out.append(BUNDLED if bundled is None else bundled)
    if env.get("CCOMM_BUILD_DIR"):
        out += [Path(env["CCOMM_BUILD_DIR"]) / LIB_SUBDIR / n for n in LIB_NAMES]
    builds: list[Path] = []
    for root in _repo_roots(starts):
        for b in root.glob(f"build*/{LIB_SUBDIR}"):
            if any((b / n).is_file() for n in LIB_NAMES):
                builds.append(b)
    builds.sort(key=lambda b: max((b / n).stat().st_mtime for n in LIB_NAMES if (b / n).is_file()),
                reverse=True)
    for b in builds:
        out += [b / n for n in LIB_NAMES]
    return out


def find_library(env: Optional[Mapping[str, str]] = None,
                 starts: Optional[Sequence[Path]] = None,
                 bundled: Optional[Path] = None) -> str:
    """Path (or soname) of libccomm to load; raises LibraryNotFoundError."""
    env = os.environ if env is None else env
    starts = [Path(__file__).resolve().parent, Path.cwd()] if starts is None else starts
    tried = candidates(env, starts, bundled)
    for p in tried:
        if p.is_file():
            return str(p)
    if env.get("CCOMM_LIBRARY"):
        raise LibraryNotFoundError(f"CCOMM_LIBRARY={env['CCOMM_LIBRARY']} does not exist")
    system = ctypes.util.find_library("ccomm")
    if system:
        return system
    if _loadable(LIB_NAMES[0]):  # libccomm0 without the ldconfig cache find_library reads
        return LIB_NAMES[0]
    where = ", ".join(str(p) for p in tried) or "no build directory"
    raise LibraryNotFoundError(
        f"libccomm.so not found (tried {where}, then the system library path). "
        "Set CCOMM_LIBRARY to the library or CCOMM_BUILD_DIR to a ccomm build directory.")


def _loadable(soname: str) -> bool:
    try:
        ctypes.CDLL(soname)
        return True
    except OSError:
        return False


_lib: Optional[ctypes.CDLL] = None
_lib_path: Optional[str] = None


def lib() -> ctypes.CDLL:
    """The loaded library, declared; loaded on first use so `import ccomm` never fails."""
    global _lib, _lib_path
    if _lib is None:
        path = find_library()
        _lib = _declare(ctypes.CDLL(path))
        _lib_path = path
    return _lib


def library_path() -> str:
    """File of the libccomm this process uses (loads it if needed): where the dynamic
    loader mapped it from, also when it was loaded by soname."""
    lib()
    assert _lib_path is not None
    try:
        with open("/proc/self/maps") as maps:
            for line in maps:
                path = line.split(maxsplit=5)[-1].strip()
                if os.path.basename(path).startswith("libccomm.so"):
                    return path
    except OSError:
        pass
    return _lib_path


def _declare(L: ctypes.CDLL) -> ctypes.CDLL:
    vp, cp, i32, u32 = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int32, ctypes.c_uint32
    L.ccomm_open.argtypes = [cp, u32, ctypes.POINTER(vp)]
    L.ccomm_open.restype = ctypes.c_int
    L.ccomm_close.argtypes = [vp]
    L.ccomm_close.restype = None
    L.ccomm_strerror.argtypes = [ctypes.c_int]
    L.ccomm_strerror.restype = cp
    L.ccomm_find.argtypes = [vp, cp]
    L.ccomm_find.restype = i32
    L.ccomm_signal_count.argtypes = [vp]
    L.ccomm_signal_count.restype = ctypes.c_int
    L.ccomm_describe.argtypes = [vp, i32, ctypes.POINTER(SignalDesc)]
    L.ccomm_describe.restype = ctypes.c_int
    L.ccomm_node_name.argtypes = [vp]
    L.ccomm_node_name.restype = cp
    L.ccomm_read.argtypes = [vp, i32, vp, ctypes.c_size_t, ctypes.POINTER(Info)]
    L.ccomm_read.restype = ctypes.c_int
    L.ccomm_write.argtypes = [vp, i32, vp, ctypes.c_size_t]
    L.ccomm_write.restype = ctypes.c_int
    # ctypes releases the GIL during foreign calls: other threads run while this blocks.
    L.ccomm_wait.argtypes = [vp, ctypes.c_int]
    L.ccomm_wait.restype = ctypes.c_int
    L.ccomm_set_time.argtypes = [vp, ctypes.c_int64]
    L.ccomm_set_time.restype = ctypes.c_int
    L.ccomm_now.argtypes = []
    L.ccomm_now.restype = ctypes.c_int64
    L.ccomm_daemon_alive.argtypes = [vp]
    L.ccomm_daemon_alive.restype = ctypes.c_int
    L.ccomm_node_count.argtypes = [vp]
    L.ccomm_node_count.restype = ctypes.c_int
    L.ccomm_view_open.argtypes = [vp, ctypes.POINTER(vp)]
    L.ccomm_view_open.restype = ctypes.c_int
    L.ccomm_view_close.argtypes = [vp]
    L.ccomm_view_close.restype = None
    L.ccomm_view_get_node.argtypes = [vp, ctypes.c_int, ctypes.POINTER(ViewNode)]
    L.ccomm_view_get_node.restype = ctypes.c_int
    L.ccomm_view_get_signal.argtypes = [vp, ctypes.c_int, i32, ctypes.POINTER(ViewSignal)]
    L.ccomm_view_get_signal.restype = ctypes.c_int
    L.ccomm_view_get_counters.argtypes = [vp, ctypes.POINTER(ViewCounters)]
    L.ccomm_view_get_counters.restype = ctypes.c_int
    L.ccomm_history_depth.argtypes = [vp, i32]
    L.ccomm_history_depth.restype = ctypes.c_int
    L.ccomm_history_start.argtypes = [vp, i32, u32, ctypes.POINTER(HistoryCursor)]
    L.ccomm_history_start.restype = ctypes.c_int
    L.ccomm_history_read.argtypes = [vp, i32, ctypes.POINTER(HistoryCursor), vp, ctypes.c_size_t,
                                     ctypes.POINTER(HistoryInfo)]
    L.ccomm_history_read.restype = ctypes.c_int
    return L
