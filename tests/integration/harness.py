# SPDX-License-Identifier: Apache-2.0
"""Two-node harness for ccommd integration tests: network namespaces joined by a veth
pair (eth0 inside each, as on the boards), one ccommd per namespace, CLI helpers.

Everything created here is removed again, also when a test fails."""
import json
import os
import signal
import subprocess
import time
import uuid

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
NETNS_PAIR = os.path.join(ROOT, "scripts", "netns-pair")
BUILD = os.environ.get("CCOMM_BUILD_DIR", os.path.join(ROOT, "build", "release"))  # docs/testing.md
BIN = os.path.join(BUILD, "bin")
DEFAULT_CONFIG = os.path.join(ROOT, "dist", "signals.xml")


def _sanitizer():
    try:
        with open(os.path.join(BUILD, "CMakeCache.txt")) as f:
            for line in f:
                if line.startswith("CCOMM_SANITIZE:"):
                    return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return ""


# Sanitized builds run several times slower: timing-based bounds are relaxed there,
# correctness checks (values, counters, wire loss) stay exact.
SANITIZED = _sanitizer() != ""


def python_env(env):
    """`env` for a Python process that loads this build's libccomm through ctypes: a
    sanitized library needs its runtime loaded first (python3 itself is not sanitized)."""
    env = dict(env)
    san = _sanitizer()
    if san:
        lib = {"address": "libasan.so", "thread": "libtsan.so"}[san]
        path = subprocess.run(["c++", "-print-file-name=" + lib], capture_output=True, text=True).stdout.strip()
        env["LD_PRELOAD"] = path
        if san == "address":
            env["ASAN_OPTIONS"] = "detect_leaks=0"  # the interpreter's own allocations
    return env


def run(cmd, check=True, **kw):
    return subprocess.run(cmd, check=check, capture_output=True, text=True, **kw)


def sweep_stale():
    """Removes namespaces and segments of earlier runs whose test process is gone (killed
    before it could clean up): their names carry the creating pid."""
    try:
        names = [l.split()[0] for l in run(["ip", "netns", "list"], check=False).stdout.splitlines() if l.strip()]
    except OSError:
        return
    for ns in names:
        parts = ns.split("-")
        if len(parts) == 4 and parts[0] == "cci" and parts[1].isdigit() and not os.path.exists("/proc/" + parts[1]):
            run(["ip", "netns", "del", ns], check=False)
    for f in os.listdir("/dev/shm"):
        parts = f.split("-")
        if len(parts) >= 3 and parts[0] == "cci" and parts[1].isdigit() and not os.path.exists("/proc/" + parts[1]):
            try:
                os.unlink("/dev/shm/" + f)
            except OSError:
                pass


_swept = False


class NodePair:
    """control (10.42.0.1) and planner (10.42.0.2) in namespaces <tag>-c / <tag>-p."""

    def __init__(self, config=DEFAULT_CONFIG, transport=None, env=None, preload=None):
        global _swept
        if not _swept:
            _swept = True
            sweep_stale()
        tag = "cci-%d-%s" % (os.getpid(), uuid.uuid4().hex[:6])
        self.ns = {"control": tag + "-c", "planner": tag + "-p"}
        self.config = config
        self.transport = transport
        self.env = dict(os.environ)
        self.env["CCOMM_SHM_PREFIX"] = "/" + tag + "."
        self.env.update(env or {})
        self.preload = preload
        self.daemons = {}
        self.logs = {}
        self.bg = []

    def __enter__(self):
        c, p = self.ns["control"], self.ns["planner"]
        try:
            # The one two-board network of tests, bench and demo.
            run([NETNS_PAIR, "up", c, p, "--ip-a", "10.42.0.1/24", "--ip-b", "10.42.0.2/24"])
        except BaseException:
            self.__exit__(None, None, None)  # a half-made pair leaves nothing behind
            raise
        return self

    def __exit__(self, *exc):
        for proc in self.bg:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        for node in list(self.daemons):
            self.stop(node)
        run([NETNS_PAIR, "down", *self.ns.values()], check=False)
        for node in self.ns:
            for suffix in ("", ".view", ".lock"):  # the segment, the system view, the node lock
                path = "/dev/shm/" + self.env["CCOMM_SHM_PREFIX"].lstrip("/") + node + suffix
                if os.path.exists(path):
                    os.unlink(path)

    def exec_prefix(self, node):
        return ["ip", "netns", "exec", self.ns[node]]

    def start(self, node, extra=(), wait=True):
        cmd = self.exec_prefix(node) + [os.path.join(BIN, "ccommd"), "--node", node, "--no-rt",
                                        "-c", self.config] + list(extra)
        if self.transport:
            cmd += ["--transport", self.transport]
        env = dict(self.env)
        if self.preload:
            env["LD_PRELOAD"] = self.preload
            env["CCOMM_ALLOC_REPORT"] = "/tmp/%s-%s.alloc" % (self.ns[node], node)
        log = open("/tmp/%s.log" % self.ns[node], "w")
        self.logs[node] = log.name
        self.daemons[node] = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT)
        if wait:
            self.wait_ready(node)

    def wait_ready(self, node, timeout=5.0):
        deadline = time.time() + timeout
        while time.time() < deadline:
            r = self.cli(node, "stats", "--json", check=False)
            if r.returncode == 0 and json.loads(r.stdout)["daemon_alive"]:
                return
            if self.daemons[node].poll() is not None:
                raise AssertionError("ccommd %s exited: %s" % (node, self.log(node)))
            time.sleep(0.05)
        raise AssertionError("ccommd %s not ready: %s" % (node, self.log(node)))

    def stop(self, node, sig=signal.SIGTERM):
        proc = self.daemons.pop(node, None)
        if proc and proc.poll() is None:
            proc.send_signal(sig)
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                gdb = run(["gdb", "-p", str(proc.pid), "-batch", "-ex", "thread apply all bt"], check=False)
                bt = gdb.stdout + gdb.stderr[-2000:]  # why gdb could not attach, if it could not
                print("ccommd %s stuck; log:\n%s\nbacktrace:\n%s" % (node, self.log(node), bt))
                proc.kill()
                proc.wait()
                raise AssertionError("ccommd %s did not stop on %s" % (node, sig))
        return proc.returncode if proc else None

    def log(self, node):
        with open(self.logs[node]) as f:
            return f.read()

    def cli(self, node, *args, check=True, timeout=20):
        return run(self.exec_prefix(node) + [os.path.join(BIN, "ccomm"), "--node", node] + list(args),
                   check=check, env=self.env, timeout=timeout)

    def spawn(self, node, *args, tool="ccomm"):
        proc = subprocess.Popen(self.exec_prefix(node) + [os.path.join(BIN, tool), "--node", node] + list(args),
                                env=self.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.bg.append(proc)
        return proc

    def stats(self, node):
        return json.loads(self.cli(node, "stats", "--json").stdout)

    def echo_once(self, node, signal_name):
        """(value, status) of a signal as an app on `node` reads it now."""
        out = self.cli(node, "echo", signal_name, "--once").stdout.split()
        return out[1], out[2].rstrip("*")

    def link(self, node, up):
        run(["ip", "-n", self.ns[node], "link", "set", "eth0", "up" if up else "down"])


def signal_stats(stats, name):
    return next(s for s in stats["signals"] if s["name"] == name)


def peer_stats(stats, name):
    return next(p for p in stats["peers"] if p["name"] == name)


def wait_for(predicate, timeout, interval=0.01):
    """Polls until predicate() is truthy; returns seconds taken (never 0.0, which callers'
    `assert wait_for(...)` would read as a timeout), or None on timeout."""
    start = time.time()
    while time.time() - start < timeout:
        if predicate():
            return max(time.time() - start, 1e-9)
        time.sleep(interval)
    return None
