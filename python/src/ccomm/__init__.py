# SPDX-License-Identifier: Apache-2.0
"""ccomm: read and write the named signals of a ccomm node from Python.

    with ccomm.Client("planner") as c:
        r = c.read("wheel0_pos")         # Reading(value, status, seq, age_ns, ...)
        c.write("wheel0_vel_sp", 0.3)
        c.wait(timeout=0.1)              # until any signal of the node changes
        r = c["wheel0_pos"].wait(1.0)    # until this one has a new value (or None)
        for ev in c["mode_request"].events():   # every event as it comes
            ...
        r = await c["wheel0_pos"].wait_async()  # asyncio; also aevents(), dispatch_async()

The library (libccomm.so) is loaded on first use: $CCOMM_LIBRARY, the one bundled in a
binary wheel, $CCOMM_BUILD_DIR/lib, the build directories of an enclosing source tree,
then the system (libccomm0).
"""
from ._native import LibraryNotFoundError, find_library, library_path
from ._errors import (
    BusyError,
    CcommError,
    CorruptError,
    DaemonNotRunningError,
    InvalidArgumentError,
    NotFoundError,
    NotProducerError,
    QueueFullError,
    RetiredError,
    SystemCallError,
    TypeMismatchError,
    VersionError,
)
from .client import Client, Reading, Signal, SignalInfo, SignalType, Status
from .history import History, HistoryReading
from .realtime import RealtimeResult, realtime_setup, sleep_until

# The one version of the Python package: pyproject.toml reads it, and scripts/package
# checks that it equals the CMake project version and debian/changelog.
__version__ = "0.1.0"

__all__ = [
    "BusyError", "CcommError", "Client", "CorruptError", "DaemonNotRunningError", "History", "HistoryReading",
    "InvalidArgumentError",
    "LibraryNotFoundError",
    "NotFoundError", "NotProducerError", "QueueFullError", "Reading", "RealtimeResult", "RetiredError", "Signal",
    "SignalInfo", "SignalType", "Status", "SystemCallError", "TypeMismatchError", "VersionError",
    "find_library", "library_path", "open", "realtime_setup", "sleep_until",
]


def open(node: "str | None" = None, *, no_doorbell: bool = False,  # noqa: A001
         batch: bool = False, check_daemon: bool = True) -> Client:
    """Client(node): attaches to the node's ccommd segment."""
    return Client(node, no_doorbell=no_doorbell, batch=batch, check_daemon=check_daemon)
