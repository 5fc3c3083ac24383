# SPDX-License-Identifier: Apache-2.0
"""ccomm: read and write the named signals of a ccomm node from Python.

    with ccomm.Client("planner") as c:
        r = c.read("wheel0_pos")         # Reading(value, status, seq, age_ns, ...)
        c.write("wheel0_vel_sp", 0.3)
        c.wait(timeout=0.1)              # until a signal changes

The library (libccomm.so) is loaded on first use: $CCOMM_LIBRARY, $CCOMM_BUILD_DIR/lib,
the build directories of an enclosing source tree, then the system.
"""
from ._native import LibraryNotFoundError, find_library
from .client import (
    BusyError,
    CcommError,
    Client,
    InvalidArgumentError,
    NotFoundError,
    NotProducerError,
    QueueFullError,
    Reading,
    RetiredError,
    Signal,
    SignalInfo,
    SignalType,
    Status,
    SystemCallError,
    TypeMismatchError,
    VersionError,
)

__version__ = "0.1.0"

__all__ = [
    "BusyError", "CcommError", "Client", "InvalidArgumentError", "LibraryNotFoundError",
    "NotFoundError", "NotProducerError", "QueueFullError", "Reading", "RetiredError", "Signal",
    "SignalInfo", "SignalType", "Status", "SystemCallError", "TypeMismatchError", "VersionError",
    "find_library", "open",
]


def open(node: "str | None" = None, *, no_doorbell: bool = False) -> Client:  # noqa: A001
    """Client(node): attaches to the node's ccommd segment."""
    return Client(node, no_doorbell=no_doorbell)
