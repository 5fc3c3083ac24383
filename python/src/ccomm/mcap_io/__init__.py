# SPDX-License-Identifier: Apache-2.0
"""MCAP recording and replay of ccomm signals (ccomm-record, ccomm-replay). They use the
ccomm package's binding (ccomm._native, ccomm.Client) like any other program.

schema    what a recording holds: one channel per signal, JSON messages described by a
          JSON Schema, so Foxglove, PlotJuggler and the `mcap` reader need no ccomm
writer    the writer process: turns captured records into MCAP messages, rotates files,
          reports progress
recording reads a recording back (for replay) and recovers a truncated one
"""


def require_mcap(prog: str) -> bool:
    """False (and a message saying what to install) when the `mcap` package is missing."""
    import importlib.util
    import sys
    if importlib.util.find_spec("mcap") is None:
        print(f"{prog}: needs the Python package 'mcap' (pip install 'ccomm[record]', which "
              "pins mcap, lz4 and zstandard)", file=sys.stderr)
        return False
    return True
