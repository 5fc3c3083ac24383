# SPDX-License-Identifier: Apache-2.0
"""The public WebSocket port: a relay in front of the foxglove-sdk server that accepts the
Foxglove WebSocket protocol under both of its names.

foxglove-sdk answers HTTP 400 to a client that does not offer "foxglove.sdk.v1", the
name it gave the protocol; the public specification (and Lichtblick, the ws-protocol
clients, foxglove_bridge 0.8 users) call the same protocol "foxglove.websocket.v1". The
relay reads each client's upgrade request; a client offering only the old name is
offered to the SDK under the new one, and the SDK's answer names the client's choice
back (a WebSocket client drops a connection whose server picks a protocol it did not
offer). After the handshake bytes are copied unchanged both ways, with back-pressure: a
slow client stalls its own relay only, and the SDK's per-client backlog decides what it
drops, as without the relay. The SDK itself listens on loopback only."""
from __future__ import annotations

import asyncio
import threading
from typing import List, Optional, Tuple

SDK_NAME = "foxglove.sdk.v1"
SPEC_NAME = "foxglove.websocket.v1"
_HEAD_LIMIT = 64 * 1024   # an upgrade request larger than this is refused
_HEAD_TIMEOUT_S = 10.0    # a client that never finishes its request cannot pin a task
_HEADER = b"sec-websocket-protocol"


def offered_protocols(head: bytes) -> List[str]:
    """The subprotocols a request head offers, in order (every Sec-WebSocket-Protocol line)."""
    names: List[str] = []
    for line in head.split(b"\r\n")[1:]:
        key, sep, value = line.partition(b":")
        if sep and key.strip().lower() == _HEADER:
            names += [v.strip() for v in value.decode("latin-1").split(",") if v.strip()]
    return names


def _set_protocol(head: bytes, name: str) -> bytes:
    """`head` with its Sec-WebSocket-Protocol lines replaced by one naming `name`."""
    lines = head.rstrip(b"\r\n").split(b"\r\n")
    kept = [ln for ln in lines if ln.partition(b":")[0].strip().lower() != _HEADER or not ln.partition(b":")[1]]
    kept.insert(1, b"Sec-WebSocket-Protocol: " + name.encode())
    return b"\r\n".join(kept) + b"\r\n\r\n"


def rewrite_request(head: bytes) -> Tuple[bytes, Optional[str]]:
    """(the request to send to the SDK, the name to give back in its answer or None)."""
    offered = offered_protocols(head)
    if SDK_NAME in offered or SPEC_NAME not in offered:
        return head, None  # the SDK's own name, or not ours at all: the SDK decides
    return _set_protocol(head, SDK_NAME), SPEC_NAME


def rewrite_response(head: bytes, name: str) -> bytes:
    """The SDK's handshake answer naming `name` as the chosen subprotocol."""
    if SDK_NAME not in offered_protocols(head):
        return head  # a refusal: passed on as it is
    return _set_protocol(head, name)


class SubprotocolRelay:
    """Listens on (host, port) (0: any free port) and relays every connection to the
    foxglove-sdk server on 127.0.0.1:backend_port. Runs its own event loop thread."""

    def __init__(self, host: str, port: int, backend_port: int) -> None:
        self.backend_port = backend_port
        self.relayed = 0  #: connections handed to the SDK
        self.renamed = 0  #: of those, clients that offered only foxglove.websocket.v1
        self._loop = asyncio.new_event_loop()
        self._server = self._loop.run_until_complete(
            asyncio.start_server(self._serve, host, port, limit=_HEAD_LIMIT))
        self.port: int = self._server.sockets[0].getsockname()[1]
        self._thread = threading.Thread(target=self._loop.run_forever, name="ws-relay", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        async def close() -> None:
            self._server.close()
            for task in asyncio.all_tasks():
                if task is not asyncio.current_task():
                    task.cancel()
        if self._thread.is_alive():
            asyncio.run_coroutine_threadsafe(close(), self._loop).result(timeout=5)
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(timeout=5)
        else:
            self._server.close()

    async def _serve(self, client_r: asyncio.StreamReader, client_w: asyncio.StreamWriter) -> None:
        sdk_w: Optional[asyncio.StreamWriter] = None
        try:
            head = await asyncio.wait_for(client_r.readuntil(b"\r\n\r\n"), _HEAD_TIMEOUT_S)
            request, answer_name = rewrite_request(head)
            sdk_r, sdk_w = await asyncio.open_connection("127.0.0.1", self.backend_port, limit=_HEAD_LIMIT)
            sdk_w.write(request)
            response = await asyncio.wait_for(sdk_r.readuntil(b"\r\n\r\n"), _HEAD_TIMEOUT_S)
            if answer_name:
                response = rewrite_response(response, answer_name)
                self.renamed += 1
            self.relayed += 1
            client_w.write(response)
            await client_w.drain()
            await asyncio.gather(_copy(client_r, sdk_w), _copy(sdk_r, client_w))
        except (OSError, asyncio.IncompleteReadError, asyncio.LimitOverrunError, asyncio.TimeoutError):
            pass  # a client that went away or sent no request: only its own connection ends
        except asyncio.CancelledError:
            pass  # the server stops (stop()): the connection ends with it, nothing to report
        finally:
            for w in (client_w, sdk_w):
                if w is not None:
                    w.close()


async def _copy(src: asyncio.StreamReader, dst: asyncio.StreamWriter) -> None:
    try:
        while True:
            data = await src.read(65536)
            if not data:
                break
            dst.write(data)
            await dst.drain()  # back-pressure: at most one read's worth buffered here
    finally:
        if dst.can_write_eof():
            try:
                dst.write_eof()
            except OSError:
                pass
