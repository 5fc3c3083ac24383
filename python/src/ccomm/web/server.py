# SPDX-License-Identifier: Apache-2.0
"""The live server: a Foxglove WebSocket server (foxglove-sdk) with one JSON channel per
signal, and a small HTTP server for the page and its locally installed assets.

Threads: the sampler thread owns the ccomm Client (one handle per thread) and logs to the
channels; foxglove-sdk's own runtime serves the WebSocket clients, each with its own
bounded backlog, so a slow or vanished browser never holds up the others; the HTTP
server answers each request in a thread of its own."""
from __future__ import annotations

import json
import os
import threading
import time
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, Dict, List, Optional, Set, Tuple, cast

import foxglove
from foxglove.websocket import Capability, ServerListener, StatusLevel

from ..client import CcommError, Client, RetiredError, SignalInfo
from .sampler import Sampler, json_schema, topic_of
from .subprotocol import SubprotocolRelay

STATIC_DIR = Path(__file__).with_name("static")
# uPlot as `npm ci` installs it from this package's package.json (at build time, never
# fetched by the page): the files the page loads as /vendor/NAME.
VENDOR_FILES = {
    "uPlot.iife.min.js": ("uplot/dist/uPlot.iife.min.js", "text/javascript"),
    "uPlot.min.css": ("uplot/dist/uPlot.min.css", "text/css"),
}
DAEMON_STATUS_ID = "ccommd"
PASS_PERIOD = 0.001  #: s: sampling passes at most 1000 a second
_STATIC_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript", ".css": "text/css"}


def asset_dirs() -> List[Path]:
    """Where node_modules/uplot is looked for, in order."""
    dirs = []
    if os.environ.get("CCOMM_WEB_ASSETS"):
        dirs.append(Path(os.environ["CCOMM_WEB_ASSETS"]))
    dirs.append(Path(__file__).parent)  # `npm ci` run in the installed package
    if os.environ.get("CCOMM_BUILD_DIR"):
        dirs.append(Path(os.environ["CCOMM_BUILD_DIR"]) / "web-assets")
    dirs.append(Path("/usr/share/ccomm/web"))
    return dirs


def find_assets(explicit: Optional[str] = None) -> Tuple[Optional[Path], List[Path]]:
    """(directory holding node_modules/uplot, or None; the directories tried)."""
    tried = [Path(explicit)] if explicit else asset_dirs()
    for d in tried:
        if all((d / "node_modules" / rel).is_file() for rel, _ in VENDOR_FILES.values()):
            return d, tried
    return None, tried


class Subscriptions:
    """Who is subscribed to what, as the Foxglove server reports it (a client that
    disconnects is unsubscribed from everything). A foxglove ServerListener: it has the
    two methods it needs of that protocol (the others have defaults there)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.pairs: Set[Tuple[int, int]] = set()
        self.ever = 0

    def on_subscribe(self, client: Any, channel: Any) -> None:
        with self.lock:
            self.pairs.add((client.id, channel.id))
            self.ever += 1

    def on_unsubscribe(self, client: Any, channel: Any) -> None:
        with self.lock:
            self.pairs.discard((client.id, channel.id))

    def snapshot(self) -> Dict[str, int]:
        with self.lock:
            return {"clients": len({c for c, _ in self.pairs}), "subscriptions": len(self.pairs),
                    "subscriptions_ever": self.ever}


class LiveServer:
    """Serves `names` of `node` (None: $CCOMM_NODE, else the hostname)."""

    def __init__(self, node: Optional[str], names: Optional[List[str]], *, host: str, ws_port: int,
                 http_port: int, max_rate: float, keepalive: float, plot: Optional[List[str]],
                 assets: Optional[Path]) -> None:
        self.node, self.host, self.max_rate, self.keepalive = node, host, max_rate, keepalive
        self.assets = assets
        with Client(node) as probe:  # fails here, in the caller's thread, if ccommd is not there
            self.node_name = probe.node
            infos = probe.signals()
        by_name = {i.name: i for i in infos}
        unknown = [n for n in names or [] if n not in by_name]
        if unknown:
            raise LookupError("no signal %s on node %s (it has: %s)" % (
                ", ".join(unknown), self.node_name, ", ".join(by_name)))
        self.infos: List[SignalInfo] = [by_name[n] for n in names] if names else infos
        bad_plot = [n for n in plot or [] if n not in {i.name for i in self.infos}]
        if bad_plot:
            raise LookupError("--plot %s: not among the served signals" % ", ".join(bad_plot))
        self.plot = plot or [i.name for i in self.infos][:8]
        self.subs = Subscriptions()
        self.context = foxglove.Context()
        self.channels = {i.name: foxglove.Channel(topic_of(i.name), schema=json_schema(i),
                                                  context=self.context) for i in self.infos}
        # The SDK on loopback, behind the relay that also accepts foxglove.websocket.v1.
        self.ws = foxglove.start_server(name="ccomm " + self.node_name, host="127.0.0.1", port=0,
                                        context=self.context, server_listener=cast(ServerListener, self.subs),
                                        capabilities=[Capability.Time], message_backlog_size=1024)
        try:
            self.relay = SubprotocolRelay(host, ws_port, int(self.ws.port))
        except OSError:
            self.ws.stop()
            raise
        self.http = ThreadingHTTPServer((host, http_port), _handler(self))
        self.http.daemon_threads = True
        self.stop_event = threading.Event()
        self.published: Dict[str, int] = {i.name: 0 for i in self.infos}
        self.changes: Dict[str, int] = {i.name: 0 for i in self.infos}
        self.gaps: Dict[str, int] = {i.name: 0 for i in self.infos}
        # The newest message of each signal, for a page opened later (/last.json): the
        # protocol has no latched channels, so an event signal would otherwise show
        # "never" on that page until its next event.
        self.last: Dict[str, Dict[str, Any]] = {}
        self.sampler_error: Optional[str] = None
        self.daemon_alive: Optional[bool] = None
        self.http_refused = 0
        self.counter_lock = threading.Lock()
        self._threads = [threading.Thread(target=self.http.serve_forever, name="http", daemon=True),
                         threading.Thread(target=self._sample_loop, name="sampler", daemon=True)]

    @property
    def ws_port(self) -> int:
        return self.relay.port

    @property
    def http_port(self) -> int:
        return self.http.server_address[1]

    def start(self) -> None:
        self.relay.start()
        for t in self._threads:
            t.start()

    def stop(self) -> None:
        self.stop_event.set()
        self.http.shutdown()
        for t in self._threads:
            t.join(timeout=5)
        self.http.server_close()
        self.relay.stop()
        self.ws.stop()

    def _publish(self, name: str, message: Dict[str, Any]) -> None:
        now = time.time_ns()
        self.channels[name].log(message, log_time=now)
        self.last[name] = {"log_time_ns": now, "message": message}  # one dict store: atomic

    def _sample_loop(self) -> None:
        """Wakes on any change of the node (ccomm_wait), when a change held back by
        --max-rate is due, or every 100 ms (a value going stale changes nothing in memory).
        --max-rate limits each signal's messages (Sampler.min_interval), not the passes: a
        limit on the passes at a signal's own rate made the passes lock onto its writes
        out of phase (a 100 Hz signal at the 100 Hz default arrived 5 ms late at p50).
        Passes are at most one per PASS_PERIOD (the CPU bound), so a write during a pass
        waits that long at most."""
        min_period = min(PASS_PERIOD, 1.0 / self.max_rate)
        while not self.stop_event.is_set():
            try:
                with Client(self.node) as client:
                    sampler = Sampler(client, [i.name for i in self.infos], self._publish, self.keepalive,
                                      min_interval=1.0 / self.max_rate)
                    try:
                        base, base_changes, base_gaps = dict(self.published), dict(self.changes), dict(self.gaps)
                        while not self.stop_event.is_set():
                            timeout = 0.1
                            if sampler.next_due is not None:
                                timeout = max(0.0, min(timeout, sampler.next_due - time.monotonic()))
                            client.wait(timeout=timeout)
                            started = time.monotonic()
                            sampler.poll(started)
                            self._watch_daemon(client.daemon_alive)
                            for name, n in sampler.published.items():
                                self.published[name] = base[name] + n
                            for name, n in sampler.changes.items():
                                self.changes[name] = base_changes[name] + n
                            for name, n in sampler.gaps.items():
                                self.gaps[name] = base_gaps[name] + n
                            self.ws.broadcast_time(time.time_ns())
                            rest = min_period - (time.monotonic() - started)
                            if rest > 0:
                                self.stop_event.wait(rest)
                    finally:
                        sampler.close()  # its view before the client
            except RetiredError:
                print("ccomm-web: ccommd restarted with a new configuration; attaching again", flush=True)
            except CcommError as e:
                self.sampler_error = str(e)
                print("ccomm-web: %s; retrying in 1 s" % e, flush=True)
                self.stop_event.wait(1.0)

    def _watch_daemon(self, alive: bool) -> None:
        """A stopped ccommd leaves its last values in memory, going stale: every client
        is told why (a Foxglove status message, shown in its problems list and the page)."""
        if alive == self.daemon_alive:
            return
        first, self.daemon_alive = self.daemon_alive is None, alive
        if alive:
            self.ws.remove_status([DAEMON_STATUS_ID])
        else:
            self.ws.publish_status("ccommd of node %s is not running (no heartbeat for 1 s): values are the "
                                   "last it stored" % self.node_name, StatusLevel.Warning, DAEMON_STATUS_ID)
        if not (first and alive):
            print("ccomm-web: ccommd of node %s %s" % (self.node_name, "is running" if alive else "stopped"),
                  flush=True)

    def config(self) -> Dict[str, Any]:
        return {"node": self.node_name, "ws_port": self.ws_port, "max_rate": self.max_rate,
                "keepalive_s": self.keepalive, "plot": self.plot,
                "signals": [{"name": i.name, "topic": topic_of(i.name), "type": i.type.name.lower(),
                             "count": i.count, "event": i.is_event, "stale_after_ms": i.stale_after_ms,
                             "producer": i.producer} for i in self.infos]}

    def stats(self) -> Dict[str, Any]:
        s: Dict[str, Any] = {"published": dict(self.published), "changes": dict(self.changes),
                             "gaps": dict(self.gaps),
                             "http_refused": self.http_refused,
                             "ws_connections": self.relay.relayed, "ws_renamed": self.relay.renamed,
                             "sampler_error": self.sampler_error, "daemon_alive": self.daemon_alive}
        s.update(self.subs.snapshot())
        return s


def _handler(server: LiveServer) -> type:
    class Handler(BaseHTTPRequestHandler):
        """GET only: the page, its static files, /vendor (uPlot), /config.json, /stats.json,
        /last.json (the newest message of each signal with its log time)."""

        server_version = "ccomm-web"
        timeout = 10  # seconds a connection may idle: one that never sends cannot pin a thread

        def log_message(self, format: str, *args: Any) -> None:  # noqa: A002
            pass  # one line per request would drown the start-up lines; refusals are counted

        def send_error(self, code: int, message: Optional[str] = None, explain: Optional[str] = None) -> None:
            with server.counter_lock:  # every refused request (400, 404, 501...), in /stats.json
                server.http_refused += 1
            super().send_error(code, message, explain)

        def do_HEAD(self) -> None:
            self.do_GET(body=False)

        def do_GET(self, body: bool = True) -> None:
            path = self.path.split("?", 1)[0]
            if path == "/":
                path = "/index.html"
            if path == "/config.json":
                return self._send(json.dumps(server.config()).encode(), "application/json", body)
            if path == "/last.json":
                return self._send(json.dumps(dict(server.last)).encode(), "application/json", body)
            if path == "/stats.json":
                return self._send(json.dumps(server.stats()).encode(), "application/json", body)
            if path.startswith("/vendor/") and path[8:] in VENDOR_FILES:
                rel, ctype = VENDOR_FILES[path[8:]]
                if server.assets is None:
                    return self.send_error(HTTPStatus.NOT_FOUND, "uPlot is not installed (see ccomm-web --help)")
                return self._send((server.assets / "node_modules" / rel).read_bytes(), ctype, body)
            name = path.lstrip("/")
            f = STATIC_DIR / name
            if "/" not in name and f.suffix in _STATIC_TYPES and f.is_file():
                return self._send(f.read_bytes(), _STATIC_TYPES[f.suffix], body)
            self.send_error(HTTPStatus.NOT_FOUND)

        def _send(self, data: bytes, ctype: str, body: bool) -> None:
            try:
                self.send_response(HTTPStatus.OK)
                self.send_header("Content-Type", ctype)
                self.send_header("Content-Length", str(len(data)))
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                if body:
                    self.wfile.write(data)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the browser went away mid-answer: nothing to do for it

    return Handler
