# SPDX-License-Identifier: Apache-2.0
"""Finds and loads libccomm.so and declares the C API for ctypes: the one Python binding
of ccomm.h. Every public struct of ccomm.h has its ctypes.Structure here (python/tests/
test_layout.py compiles the header and compares every size and offset), and every
function its declaration in _declare(). Struct pointers are declared c_void_p, so a caller
passes ctypes.byref(struct) or a plain address (the record and replay loops pass
integers: a call then costs one foreign call and no Python object)."""
from __future__ import annotations

import ctypes
import ctypes.util
import os
import struct
from pathlib import Path
from typing import Any, Dict, Mapping, Optional, Sequence, Type

# Windows: ccomm.dll in bin/ of a build or of the zip (docs/install.md "Windows").
LIB_NAMES = ("ccomm.dll",) if os.name == "nt" else ("libccomm.so.0", "libccomm.so")
LIB_SUBDIR = "bin" if os.name == "nt" else "lib"
OPEN_NO_DOORBELL = 0x1  # CCOMM_OPEN_NO_DOORBELL
OPEN_BATCH = 0x2  # CCOMM_OPEN_BATCH: writes leave together at ccomm_flush()


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


class SignalStats(ctypes.Structure):  # ccomm_signal_stats
    _fields_ = [
        ("writes", ctypes.c_uint64),
        ("write_errors", ctypes.c_uint64),
        ("tx", ctypes.c_uint64),
        ("coalesced", ctypes.c_uint64),
        ("rx", ctypes.c_uint64),
        ("lost", ctypes.c_uint64),
        ("overflow", ctypes.c_uint64),
        ("stale_transitions", ctypes.c_uint64),
        ("corrupt", ctypes.c_uint64),
        ("last_rx_age_ns", ctypes.c_int64),
        ("stale", ctypes.c_int32),
        ("fragments_refused", ctypes.c_uint64),
        ("values_incomplete", ctypes.c_uint64),
    ]


class PeerStats(ctypes.Structure):  # ccomm_peer_stats
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("is_self", ctypes.c_int32),
        ("alive", ctypes.c_int32),
        ("frames_rx", ctypes.c_uint64),
        ("frames_tx", ctypes.c_uint64),
        ("frames_lost", ctypes.c_uint64),
        ("frames_reordered", ctypes.c_uint64),
        ("heartbeats_rx", ctypes.c_uint64),
        ("down_transitions", ctypes.c_uint64),
        ("last_rx_age_ns", ctypes.c_int64),
    ]


class PeerClock(ctypes.Structure):  # ccomm_peer_clock
    _fields_ = [("known", ctypes.c_int32), ("reserved", ctypes.c_int32), ("offset_floor_ns", ctypes.c_int64),
                ("queue_delay_ns", ctypes.c_uint64), ("queue_delay_max_ns", ctypes.c_uint64),
                ("frames_delayed", ctypes.c_uint64)]


class ClockState(ctypes.Structure):  # ccomm_clock_state
    _fields_ = [("state", ctypes.c_int32), ("port_state", ctypes.c_int32),
                ("offset_ns", ctypes.c_int64), ("path_delay_ns", ctypes.c_int64)]


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
        ("forwarded", ctypes.c_int32),
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
        ("clock_state", ctypes.c_int32),
        ("reserved", ctypes.c_int32),
        ("clock_error_ns", ctypes.c_int64),
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


class ProductionAge(ctypes.Structure):
    """ccomm_production_age."""
    _fields_ = [("code", ctypes.c_int32), ("known", ctypes.c_int32), ("age_ns", ctypes.c_int64),
                ("error_ns", ctypes.c_int64), ("production_time_ns", ctypes.c_int64)]


# The public structs of ccomm.h by their C name: what the layout test compares.
STRUCTS: Dict[str, Type[ctypes.Structure]] = {
    "ccomm_info": Info, "ccomm_signal_desc": SignalDesc, "ccomm_history_cursor": HistoryCursor,
    "ccomm_peer_clock": PeerClock, "ccomm_clock_state": ClockState,
    "ccomm_history_info": HistoryInfo, "ccomm_signal_stats": SignalStats,
    "ccomm_peer_stats": PeerStats, "ccomm_view_node": ViewNode,
    "ccomm_view_signal": ViewSignal, "ccomm_view_counters": ViewCounters,
    "ccomm_production_age": ProductionAge,
}

_STRUCT_CODES: Dict[Any, str] = {ctypes.c_int32: "i", ctypes.c_uint32: "I", ctypes.c_int64: "q",
                                 ctypes.c_uint64: "Q", ctypes.c_double: "d"}


def unpack_format(cls: Type[ctypes.Structure]) -> str:
    """struct format of a ctypes structure without padding (for struct.unpack_from on the
    structure itself: one call for every field, as the record loop needs)."""
    fmt = "<" + "".join(_STRUCT_CODES[t] for _n, t in cls._fields_)  # type: ignore[misc]
    if struct.calcsize(fmt) != ctypes.sizeof(cls):
        raise TypeError(f"{cls.__name__} has padding: no struct format")
    return fmt


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
    $CCOMM_BUILD_DIR/lib, the newest build/*/lib of an enclosing source tree (build trees
    are build/NAME/, docs/testing.md). (The system search comes after these.)"""
    out: list[Path] = []
    if env.get("CCOMM_LIBRARY"):
        return [Path(env["CCOMM_LIBRARY"])]
    out.append(BUNDLED if bundled is None else bundled)
    if env.get("CCOMM_BUILD_DIR"):
        out += [Path(env["CCOMM_BUILD_DIR"]) / LIB_SUBDIR / n for n in LIB_NAMES]
    builds: list[Path] = []
    for root in _repo_roots(starts):
        for b in root.glob(f"build/*/{LIB_SUBDIR}"):
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
    vp, cp, i32, u32, i64 = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int32, ctypes.c_uint32, ctypes.c_int64
    sz, c_int = ctypes.c_size_t, ctypes.c_int
    # name: (argument types, result type); every struct pointer is vp (see the docstring).
    # The growable structs are filled by the *_sized calls, given ctypes.sizeof of the
    # structure here (ccomm.h, "Growable structs"): a newer library never writes past it.
    api: Dict[str, Any] = {
        "ccomm_open": ([cp, u32, ctypes.POINTER(vp)], c_int),
        "ccomm_close": ([vp], None),
        "ccomm_strerror": ([c_int], cp),
        "ccomm_type_name": ([i32], cp),
        "ccomm_type_size": ([i32], u32),
        "ccomm_type_from_name": ([cp], c_int),
        "ccomm_find": ([vp, cp], i32),
        "ccomm_signal_count": ([vp], c_int),
        "ccomm_describe_sized": ([vp, i32, vp, sz], c_int),
        "ccomm_node_name": ([vp], cp),
        "ccomm_read": ([vp, i32, vp, sz, vp], c_int),
        "ccomm_write": ([vp, i32, vp, sz], c_int),
        "ccomm_flush": ([vp], c_int),
        # ctypes releases the GIL during foreign calls: other threads run while this blocks.
        "ccomm_wait": ([vp, c_int], c_int),
        "ccomm_set_time": ([vp, i64], c_int),
        "ccomm_now": ([], i64),
        "ccomm_realtime_setup": ([i32, i32, i32, ctypes.POINTER(i32)], c_int),
        # ctypes releases the GIL here too: the sleep holds up no other thread.
        "ccomm_sleep_until": ([i64], c_int),
        "ccomm_daemon_alive": ([vp], c_int),
        "ccomm_daemon_generation": ([vp], u32),
        "ccomm_get_signal_stats_sized": ([vp, i32, vp, sz], c_int),
        "ccomm_node_count": ([vp], c_int),
        "ccomm_get_peer_stats_sized": ([vp, c_int, vp, sz], c_int),
        "ccomm_get_peer_clock_sized": ([vp, c_int, vp, sz], c_int),
        "ccomm_get_clock_state_sized": ([vp, vp, sz], c_int),
        "ccomm_clock_state_name": ([c_int], cp),
        "ccomm_production_age_name": ([c_int], cp),
        "ccomm_view_open": ([vp, ctypes.POINTER(vp)], c_int),
        "ccomm_view_close": ([vp], None),
        "ccomm_view_get_node_sized": ([vp, c_int, vp, sz], c_int),
        "ccomm_view_get_signal_sized": ([vp, c_int, i32, vp, sz], c_int),
        "ccomm_view_get_counters_sized": ([vp, vp, sz], c_int),
        "ccomm_view_production_age_sized": ([vp, i32, vp, vp, sz], c_int),
        "ccomm_history_depth": ([vp, i32], c_int),
        "ccomm_history_start": ([vp, i32, u32, vp], c_int),
        "ccomm_history_read": ([vp, i32, vp, vp, sz, vp], c_int),
    }
    for name, (argtypes, restype) in api.items():
        f = getattr(L, name)
        f.argtypes, f.restype = argtypes, restype
    return L
