# SPDX-License-Identifier: Apache-2.0
"""Running the bench programs: foreground measurement, background partner, netns.

Every process started here is remembered and ended by its own pid when the run
ends (normally, on an exception, or on SIGINT/SIGTERM), never by name.
"""

import os
import signal
import subprocess
import time

from . import results

EXIT_SKIP = 4
_HERE = os.path.dirname(os.path.abspath(__file__))
NETNS_SH = os.path.join(_HERE, "netns.sh")

_children = []


class Skip(Exception):
    """A measurement cannot run here (no root, missing program or facility)."""


class Failed(Exception):
    """A measurement ran and failed."""


def start_background(argv, log_path):
    """Start a partner process (echo, iox-roudi) with output to log_path."""
    log = open(log_path, "w")
    log.write("$ %s\n" % " ".join(argv))  # the exact command, for the reports
    log.flush()
    p = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                         start_new_session=True)
    log.close()
    p.log_path = log_path
    _children.append(p)
    return p


def stop(p, grace=2.0):
    """End one process we started: wait `grace` s for it to exit by itself, then SIGTERM, then SIGKILL."""
    if p is None:
        return None
    try:
        return p.wait(timeout=grace)
    except subprocess.TimeoutExpired:
        pass
    for sig, wait in ((signal.SIGTERM, 3.0), (signal.SIGKILL, 3.0)):
        try:
            # The partner runs in its own session (start_new_session): its group is its own.
            os.killpg(p.pid, sig)
        except ProcessLookupError:
            break
        try:
            return p.wait(timeout=wait)
        except subprocess.TimeoutExpired:
            continue
    return p.poll()


def stop_all():
    while _children:
        stop(_children.pop(), grace=0.2)


def forget(p):
    if p in _children:
        _children.remove(p)


def run_measurement(argv, timeout, log_path=None):
    """Run a program that prints one result line; return the validated row.

    Exit 4 means "skipped here" (e.g. no permission), anything else non-zero is a failure.
    """
    try:
        cp = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            timeout=timeout, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired as e:
        if log_path:  # what it printed before it hung
            def text(x):
                return x.decode(errors="replace") if isinstance(x, bytes) else (x or "")
            with open(log_path, "w") as f:
                f.write("$ %s\n%s\n--- stderr ---\n%s\n--- timed out after %ss ---\n" % (
                    " ".join(argv), text(e.stdout), text(e.stderr), timeout))
        raise Failed("%s timed out after %ss" % (os.path.basename(argv[0]), timeout)) from e
    if log_path:
        with open(log_path, "w") as f:
            f.write("$ %s\n%s\n--- stderr ---\n%s" % (" ".join(argv), cp.stdout, cp.stderr))
    if cp.returncode == EXIT_SKIP:
        raise Skip((cp.stderr.strip().splitlines() or ["skipped"])[-1])
    if cp.returncode != 0:
        tail = " | ".join(cp.stderr.strip().splitlines()[-3:])
        raise Failed("%s exited %d: %s" % (" ".join(argv[:4]), cp.returncode, tail))
    return results.parse_program_output(cp.stdout)


def ping_with_echo(echo_argv, echo_log, ping_argv, timeout, ping_log, echo_exit=2.0):
    """Round trips: the echo in the background, the ping measuring in the foreground.

    The echo gets `echo_exit` s to exit by itself on the ping's FIN (and print what it
    prints last, e.g. its CPU time), then it is ended. Returns the ping's row.
    """
    echo = start_background(echo_argv, echo_log)
    try:
        return run_measurement(ping_argv, timeout, ping_log)
    finally:
        stop(echo, grace=echo_exit)
        forget(echo)


def source_to_sink(sink_argv, sink_log, source_argv, source_log, timeout, sink_exit=15.0):
    """One way: the sink in the background measures and prints the row, the source in the
    foreground only sends, then a FIN; the sink gets `sink_exit` s to exit on it (or on
    its idle timeout). Both logs start with the command. Returns the sink's row.
    """
    def tail(path):
        with open(path, errors="replace") as f:
            return f.read().strip()
    sink = start_background(sink_argv, sink_log)
    try:
        with open(source_log, "w") as f:
            f.write("$ %s\n" % " ".join(source_argv))
            f.flush()
            rc = subprocess.run(source_argv, stdout=f, stderr=subprocess.STDOUT, timeout=timeout,
                                stdin=subprocess.DEVNULL).returncode
        if rc == EXIT_SKIP:
            raise Skip(tail(source_log).splitlines()[-1])
        if rc != 0:
            raise Failed("source exited %d: %s" % (rc, tail(source_log)[-300:]))
        rc = sink.wait(timeout=sink_exit)
    except subprocess.TimeoutExpired as e:
        raise Failed("one-way run timed out") from e
    finally:
        stop(sink, grace=0.5)
        forget(sink)
    if rc != 0:
        raise Failed("sink exited %d: %s" % (rc, tail(sink_log)[-300:]))
    return results.parse_program_output(tail(sink_log))


def wait_for_text(path, text, timeout, proc=None):
    """Poll a log file until it contains `text`; False on timeout or if `proc` died."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            with open(path, errors="replace") as f:
                if text in f.read():
                    return True
        except FileNotFoundError:
            pass
        if proc is not None and proc.poll() is not None:
            return False
        time.sleep(0.05)
    return False


class NetnsPair:
    """Two namespaces joined by veth (bench/benchlib/netns.sh): ns_a/ns_b, eth0 in each."""

    IP_A, IP_B = "198.18.76.1", "198.18.76.2"
    MAC_A, MAC_B = "02:cc:b0:00:00:01", "02:cc:b0:00:00:02"

    def __init__(self, prefix="ccb"):
        self.prefix = prefix
        self.ns_a, self.ns_b = prefix + "-a", prefix + "-b"
        self.up = False

    def _sh(self, cmd):
        env = dict(os.environ, CCB_PREFIX=self.prefix)
        return subprocess.run(["sh", NETNS_SH, cmd], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL)

    def __enter__(self):
        if os.geteuid() != 0:
            raise Skip("network namespaces need root")
        cp = self._sh("up")
        if cp.returncode == EXIT_SKIP:
            raise Skip(cp.stderr.strip() or "netns not available")
        if cp.returncode != 0:
            raise Failed("netns up: " + cp.stderr.strip())
        self.up = True
        return self

    def __exit__(self, *exc):
        if self.up:
            self._sh("down")
            self.up = False
        return False

    def wrap(self, side, argv):
        """argv run inside namespace 'a' or 'b'."""
        ns = self.ns_a if side == "a" else self.ns_b
        return ["ip", "netns", "exec", ns] + list(argv)
