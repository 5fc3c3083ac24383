# SPDX-License-Identifier: Apache-2.0
"""Argument types the ccomm tools (ccomm-record, ccomm-replay) share."""
from __future__ import annotations

import argparse


def fifo_priority(text: str) -> int:
    """--priority N: 0 (normal scheduling) or a SCHED_FIFO priority 1..99; anything else is
    refused at parse time (exit 2) rather than warned about and ignored."""
    try:
        n = int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 0 <= n <= 99:
        raise argparse.ArgumentTypeError(f"{n} is outside 0..99 (0: normal scheduling, 1..99: SCHED_FIFO)")
    return n
