# SPDX-License-Identifier: Apache-2.0
"""N-node harness: one network namespace per node, all on one Linux bridge (as boards on
one switch), eth0 inside each with 10.43.0.(i+1)/24, one ccommd per namespace. Used by
the fan-out and monitor tests. Everything is removed again, also when a test fails."""
import json
import os
import signal
import subprocess
import time
import uuid

from harness import BIN, run, sweep_stale


class Nodes:
    def __init__(self, names, config_text, env=None):
        sweep_stale()
        self.tag = "cci-%d-%s" % (os.getpid(), uuid.uuid4().hex[:6])
        self.names = list(names)
        self.ns = {n: "%s-%d" % (self.tag, i) for i, n in enumerate(self.names)}
        self.bridge = "ccb%s" % self.tag[-6:]
        self.config = "/tmp/%s.xml" % self.tag
        with open(self.config, "w") as f:
            f.write(config_text)
        self.env = dict(os.environ)
        self.env["CCOMM_SHM_PREFIX"] = "/" + self.tag + "."
        self.env.update(env or {})
        self.daemons, self.logs, self.bg = {}, {}, []

    @staticmethod
    def ip_of(index):
        return "10.43.0.%d" % (index + 1)

    def __enter__(self):
        try:
            run(["ip", "link", "add", self.bridge, "type", "bridge"])
            run(["ip", "link", "set", self.bridge, "up"])
            for i, n in enumerate(self.names):
                ns, host = self.ns[n], "%sv%d" % (self.bridge, i)
                run(["ip", "netns", "add", ns])
                run(["ip", "link", "add", host, "type", "veth", "peer", "name", "eth0", "netns", ns])
                run(["ip", "link", "set", host, "master", self.bridge, "up"])
                run(["ip", "-n", ns, "addr", "add", self.ip_of(i) + "/24", "dev", "eth0"])
                run(["ip", "-n", ns, "link", "set", "eth0", "up"])
                run(["ip", "-n", ns, "link", "set", "lo", "up"])
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc):
        for proc in self.bg:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        for n in list(self.daemons):
            self.stop(n)
        for ns in self.ns.values():
            run(["ip", "netns", "del", ns], check=False)
        run(["ip", "link", "del", self.bridge], check=False)
        for n in self.names:
            path = "/dev/shm/" + self.env["CCOMM_SHM_PREFIX"].lstrip("/") + n
            if os.path.exists(path):
                os.unlink(path)
        if os.path.exists(self.config):
            os.unlink(self.config)

    def exec_prefix(self, n):
        return ["ip", "netns", "exec", self.ns[n]]

    def start(self, n, wait=True):
        log = open("/tmp/%s.log" % self.ns[n], "w")
        self.logs[n] = log.name
        self.daemons[n] = subprocess.Popen(
            self.exec_prefix(n) + [os.path.join(BIN, "ccommd"), "--node", n, "--no-rt", "-c", self.config],
            env=self.env, stdout=log, stderr=subprocess.STDOUT)
        if wait:
            deadline = time.time() + 5
            while time.time() < deadline:
                r = self.cli(n, "stats", "--json", check=False)
                if r.returncode == 0 and json.loads(r.stdout)["daemon_alive"]:
                    return
                if self.daemons[n].poll() is not None:
                    raise AssertionError("ccommd %s exited: %s" % (n, self.log(n)))
                time.sleep(0.05)
            raise AssertionError("ccommd %s not ready: %s" % (n, self.log(n)))

    def stop(self, n, sig=signal.SIGTERM):
        proc = self.daemons.pop(n, None)
        if proc and proc.poll() is None:
            proc.send_signal(sig)
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
                raise AssertionError("ccommd %s did not stop" % n)

    def log(self, n):
        with open(self.logs[n]) as f:
            return f.read()

    def cli(self, n, *args, check=True, timeout=30):
        return run(self.exec_prefix(n) + [os.path.join(BIN, "ccomm"), "--node", n] + list(args),
                   check=check, env=self.env, timeout=timeout)

    def stats(self, n):
        return json.loads(self.cli(n, "stats", "--json").stdout)

    def host_veth_rx_packets(self, n):
        """Packets the bridge received from node n (its veth's host side): what n sent."""
        i = self.names.index(n)
        with open("/sys/class/net/%sv%d/statistics/rx_packets" % (self.bridge, i)) as f:
            return int(f.read())
