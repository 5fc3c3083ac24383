#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Host side of the QEMU test control channel (no network to the host needed).

  vmctl.py run  PIPE [--timeout S] -- SHELL-COMMAND   run a command on a board
  vmctl.py ping PIPE [--timeout S]                     is the board's agent answering?
  vmctl.py qmp  SOCK COMMAND [JSON-ARGS]               one QMP command to a QEMU

`run` talks to qemu-tests/guest/ccomm-test-agent through a virtio-serial port that QEMU
connects to a pair of FIFOs (PIPE.in, PIPE.out; -chardev pipe). Each way a header
line and a body of LEN bytes: "ID TIMEOUT LEN" + command, "ID STATUS LEN" + output.
The command's output is printed and its exit status returned; 125 means the board
did not answer in time or QEMU is gone (a transport failure, not the command's). Replies to earlier, abandoned
requests carry another ID and are skipped. Callers are serialized per board (flock).
"""

import fcntl
import json
import os
import re
import select
import socket
import sys
import time

TRANSPORT_FAIL = 125


def _connect(path, deadline):
    while True:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            s.connect(path)
            return s
        except OSError:
            s.close()
            if time.monotonic() >= deadline:
                raise
            time.sleep(0.1)


def _lock(path, deadline):
    # One request at a time per board: the pipes are shared by every caller.
    f = open(path + ".lock", "w")
    while True:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return f
        except BlockingIOError:
            if time.monotonic() >= deadline:
                f.close()
                return None
            time.sleep(0.02)


HEADER = re.compile(rb"^(\S+) (-?\d+) (\d+)$")


def run(path, command, timeout):
    """Runs COMMAND on the board whose control port is the QEMU pipe chardev PATH
    (PATH.in to QEMU, PATH.out from QEMU). A pipe chardev is always connected, so
    the agent's read blocks instead of polling for a host connection."""
    # The agent's own timeout first (it kills the command, then reports which threads
    # were busy, which takes a few seconds), then ours.
    deadline = time.monotonic() + timeout + 10
    req_id = "%d-%d" % (os.getpid(), int(time.monotonic() * 1e6))
    body = command.encode()
    lock = _lock(path, deadline)
    if lock is None:
        print("vmctl: %s busy for %ds" % (path, timeout), file=sys.stderr)
        return TRANSPORT_FAIL
    with lock:
        try:
            rfd = os.open(path + ".out", os.O_RDONLY | os.O_NONBLOCK)
            wfd = os.open(path + ".in", os.O_WRONLY | os.O_NONBLOCK)
        except OSError as e:
            print("vmctl: %s: %s" % (path, e), file=sys.stderr)
            return TRANSPORT_FAIL
        try:
            data = ("%s %d %d\n" % (req_id, max(1, int(timeout)), len(body))).encode() + body
            while data:
                _, w, _ = select.select([], [wfd], [], max(0, deadline - time.monotonic()))
                if not w:
                    print("vmctl: %s not accepting input" % path, file=sys.stderr)
                    return TRANSPORT_FAIL
                data = data[os.write(wfd, data):]
            buf = b""
            want = None  # (id, status, length) of the reply being read
            while True:
                while True:
                    if want is None:
                        if b"\n" not in buf:
                            break
                        line, buf = buf.split(b"\n", 1)
                        m = HEADER.match(line.strip())
                        if m:  # anything else: the rest of an abandoned reply
                            want = (m.group(1).decode(), int(m.group(2)), int(m.group(3)))
                        continue
                    if len(buf) < want[2]:
                        break
                    out, buf = buf[:want[2]], buf[want[2]:]
                    if want[0] == req_id:
                        if out and not out.endswith(b"\n"):
                            out += b"\n"
                        sys.stdout.buffer.write(out)
                        sys.stdout.flush()
                        return want[1]
                    want = None  # a reply to an earlier, abandoned request
                left = deadline - time.monotonic()
                if left <= 0:
                    print("vmctl: no answer from %s within %ds" % (path, timeout), file=sys.stderr)
                    return TRANSPORT_FAIL
                r, _, _ = select.select([rfd], [], [], left)
                if not r:
                    continue
                chunk = os.read(rfd, 1 << 20)
                if not chunk:
                    print("vmctl: %s closed (QEMU gone?)" % path, file=sys.stderr)
                    return TRANSPORT_FAIL
                buf += chunk
        finally:
            os.close(rfd)
            os.close(wfd)


def qmp(path, command, args, timeout=10):
    deadline = time.monotonic() + timeout
    s = _connect(path, deadline)
    s.settimeout(timeout)
    f = s.makefile("rwb")

    def reply():
        while True:
            line = f.readline()
            if not line:
                raise RuntimeError("QMP connection closed")
            msg = json.loads(line)
            if "return" in msg or "error" in msg:
                return msg

    f.readline()  # greeting
    f.write(b'{"execute": "qmp_capabilities"}\n')
    f.flush()
    reply()
    cmd = {"execute": command}
    if args:
        cmd["arguments"] = args
    f.write((json.dumps(cmd) + "\n").encode())
    f.flush()
    msg = reply()
    s.close()
    if "error" in msg:
        print("qmp: %s" % msg["error"].get("desc", msg["error"]), file=sys.stderr)
        return 1
    if msg.get("return"):
        print(json.dumps(msg["return"]))
    return 0


def main(argv):
    if len(argv) < 3 or argv[1] not in ("run", "ping", "qmp"):
        print(__doc__, file=sys.stderr)
        return 2
    op, path, rest = argv[1], argv[2], argv[3:]
    timeout = 60.0
    if len(rest) >= 2 and rest[0] == "--timeout":
        timeout = float(rest[1])
        rest = rest[2:]
    if op == "ping":
        return 0 if run(path, "true", timeout) == 0 else 1
    if op == "qmp":
        if not rest:
            print("qmp: COMMAND missing", file=sys.stderr)
            return 2
        try:
            return qmp(path, rest[0], json.loads(rest[1]) if len(rest) > 1 else None, timeout)
        except (OSError, RuntimeError, ValueError) as e:
            print("qmp: %s" % e, file=sys.stderr)
            return 1
    if rest and rest[0] == "--":
        rest = rest[1:]
    if not rest:
        print("run: command missing", file=sys.stderr)
        return 2
    return run(path, " ".join(rest), timeout)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
