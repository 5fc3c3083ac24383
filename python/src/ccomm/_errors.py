# SPDX-License-Identifier: Apache-2.0
"""The exceptions of the ccomm package: one per ccomm error code, each also a subclass of
the matching Python built-in where there is one."""
from __future__ import annotations

from . import _native


class CcommError(Exception):
    """A ccomm call failed; `code` is the ccomm error (< 0)."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


class InvalidArgumentError(CcommError, ValueError):
    """CCOMM_E_INVAL: bad argument."""


class NotFoundError(CcommError, LookupError):
    """CCOMM_E_NOENT: no such signal, or no segment (is ccommd running?)."""


class TypeMismatchError(CcommError, TypeError):
    """CCOMM_E_TYPE: the value does not match the signal's type or size."""


class NotProducerError(CcommError, PermissionError):
    """CCOMM_E_PERM: this node does not produce the signal."""


class QueueFullError(CcommError):
    """CCOMM_E_FULL: the event queue is full (ccommd is not forwarding)."""


class BusyError(CcommError):
    """CCOMM_E_BUSY: writers raced for every slot; retry next cycle."""


class SystemCallError(CcommError, OSError):
    """CCOMM_E_SYS: an OS call failed at open."""


class VersionError(CcommError):
    """CCOMM_E_VERSION: the segment has another layout version than the library."""


class RetiredError(CcommError):
    """CCOMM_E_RETIRED: ccommd replaced the segment (new configuration): reopen."""


class CorruptError(CcommError):
    """CCOMM_E_CORRUPT: the value in shared memory failed its check (the copy is skipped)."""


class DaemonNotRunningError(CcommError, ConnectionError):
    """A write reached shared memory but ccommd is not running (no heartbeat for a
    second): nothing forwards the value to other nodes or judges its freshness there. A
    restarted ccommd makes a new segment; this client then gets RetiredError."""


# The codes the record and replay loops and the system view compare results with (they
# raise no exception).
E_NOENT, E_FULL, E_BUSY, E_CORRUPT = -2, -5, -6, -10

_ERRORS = {-1: InvalidArgumentError, E_NOENT: NotFoundError, -3: TypeMismatchError,
           -4: NotProducerError, E_FULL: QueueFullError, E_BUSY: BusyError, -7: SystemCallError,
           -8: VersionError, -9: RetiredError, E_CORRUPT: CorruptError}


def error_text(code: int) -> str:
    """ccomm_strerror(code)."""
    msg: "bytes | None" = _native.lib().ccomm_strerror(code)
    return msg.decode() if msg else f"error {code}"


def error(code: int, what: str) -> CcommError:
    """The exception of ccomm error `code` (< 0), its message "what: error text"."""
    return _ERRORS.get(code, CcommError)(code, f"{what}: {error_text(code)}")


def _check(code: int, what: str) -> int:
    if code < 0:
        raise error(code, what)
    return code
