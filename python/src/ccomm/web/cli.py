# SPDX-License-Identifier: Apache-2.0
"""ccomm-web command line (`ccomm web ...` runs it with CCOMM_NODE set from --node)."""
from __future__ import annotations

import argparse
import signal
import sys
import threading
from typing import List, Optional

DESCRIPTION = """\
Live view of this node's ccomm signals, in a browser and in Foxglove.

Serves two things until stopped (Ctrl-C, SIGTERM):
  http://HOST:HTTP_PORT/   a page that plots the chosen signals live and shows, per
                           signal, its status (fresh / stale / never) and loss count;
                           it loads nothing from the internet (uPlot is served from the
                           assets installed at build time, see --assets)
  ws://HOST:PORT           a Foxglove WebSocket server: in Foxglove or Lichtblick, open a
                           connection "Foxglove WebSocket" to this address; one JSON
                           channel per signal, topic SIGNAL, fields as `ccomm record`
                           writes them (value, seq, status, lost, gap, ...) plus age_ns:
                           plot SIGNAL.value
"""

EPILOG = """\
A state signal is published when it changes or its status changes (at most --max-rate
messages a second per signal: a signal written faster is sampled, its seq and gap show
what was skipped; one slower than that arrives as soon as the next pass, within 1 ms of
the write on an idle machine), and at least every --keepalive seconds; every event of an
event signal is published once. An int64 value is a decimal string (exact beyond 2^53).

Assets: the page needs uPlot, installed with npm from this package's package.json:
  npm ci --prefix DIR   (DIR holding a copy of ccomm/web/package.json and package-lock.json)
then --assets DIR or CCOMM_WEB_ASSETS=DIR. Without it the page still shows the status
table; Foxglove does not need it.

Environment: CCOMM_NODE (node, when --node is not given), CCOMM_SHM_PREFIX (segment
names), CCOMM_WEB_ASSETS. Exit status: 0 stopped, 1 cannot attach or serve, 2 usage.
Examples:
  ccomm web                          every signal, page on http://127.0.0.1:8080/
  ccomm --node planner web wheel0_pos wheel0_vel_sp --host 0.0.0.0
See docs/integrations/liveview.md."""


def parse_args(argv: Optional[List[str]]) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="ccomm-web", description=DESCRIPTION, epilog=EPILOG,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("signals", nargs="*", metavar="SIGNAL", help="signals to serve (default: all)")
    p.add_argument("-n", "--node", metavar="NAME", help="node to attach to (default: $CCOMM_NODE, else hostname)")
    p.add_argument("--host", default="127.0.0.1", metavar="ADDR",
                   help="address to listen on (default 127.0.0.1; 0.0.0.0 for other machines)")
    p.add_argument("--port", type=int, default=8765, metavar="N", help="Foxglove WebSocket port (default 8765; 0: any)")
    p.add_argument("--http-port", type=int, default=8080, metavar="N", help="page port (default 8080; 0: any)")
    p.add_argument("--plot", metavar="A,B,...", help="comma-separated signals the page plots at first "
                   "(default: the first 8 served; the page can change it)")
    p.add_argument("--max-rate", type=float, default=200.0, metavar="HZ",
                   help="messages per second and signal at most (default 200: a signal written at up to "
                        "about that rate is published on each write, a faster one is sampled)")
    p.add_argument("--keepalive", type=float, default=1.0, metavar="S",
                   help="republish an unchanged signal after this many seconds (default 1)")
    p.add_argument("--assets", metavar="DIR", help="directory with node_modules/uplot (default: see below)")
    a = p.parse_args(argv)
    if not 0 < a.max_rate <= 10000:
        p.error("--max-rate must be in (0, 10000]")
    if not 0 < a.keepalive <= 3600:
        p.error("--keepalive must be in (0, 3600]")
    for name, port in (("--port", a.port), ("--http-port", a.http_port)):
        if not 0 <= port <= 65535:
            p.error("%s must be 0..65535" % name)
    return a


def main(argv: Optional[List[str]] = None) -> int:
    a = parse_args(argv)
    try:
        import foxglove  # noqa: F401
    except ImportError:
        print("ccomm-web: the Python package foxglove-sdk is missing: pip install 'ccomm[web]'",
              file=sys.stderr)
        return 1
    from ..client import CcommError
    from .server import LiveServer, find_assets

    assets, tried = find_assets(a.assets)
    if assets is None:
        print("ccomm-web: warning: uPlot not found in %s: the page will show no plot "
              "(see --help, Assets)" % ", ".join(str(d / "node_modules/uplot") for d in tried),
              file=sys.stderr)
    try:
        server = LiveServer(a.node, a.signals or None, host=a.host, ws_port=a.port, http_port=a.http_port,
                            max_rate=a.max_rate, keepalive=a.keepalive,
                            plot=[s for s in a.plot.split(",") if s] if a.plot else None, assets=assets)
    except CcommError as e:
        hint = "" if "ccommd running" in str(e) else " (is ccommd running for this node?)"
        print("ccomm-web: %s%s" % (e, hint), file=sys.stderr)
        return 1
    except LookupError as e:
        print("ccomm-web: %s" % e, file=sys.stderr)
        return 2
    except (OSError, RuntimeError) as e:  # a port in use, an address not on this machine
        print("ccomm-web: cannot listen on %s: %s" % (a.host, e), file=sys.stderr)
        return 1
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    server.start()
    shown = "localhost" if a.host in ("0.0.0.0", "::") else a.host
    print("ccomm-web: node %s, %d signals; page http://%s:%d/ ; Foxglove ws://%s:%d" % (
        server.node_name, len(server.infos), shown, server.http_port, shown, server.ws_port), flush=True)
    stop.wait()
    print("ccomm-web: stopping", flush=True)
    server.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
