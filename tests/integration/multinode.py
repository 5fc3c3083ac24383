# SPDX-License-Identifier: Apache-2.0
"""N-node harness: one network namespace per node, all on one Linux bridge (as boards on
one switch), eth0 inside each with 10.43.0.(i+1)/24, one ccommd per namespace. Used by
the fan-out and monitor tests. Everything is removed again, also when a test fails."""
import json
import os
import uuid

from harness import NodePair, run, sweep_stale


class Nodes(NodePair):
    """NodePair's daemon and CLI helpers (start, stop, cli, stats) for N nodes."""

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
        self.transport, self.preload = None, None

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
        NodePair.__exit__(self, *exc)  # processes, daemons, namespaces, segments
        run(["ip", "link", "del", self.bridge], check=False)
        if os.path.exists(self.config):
            os.unlink(self.config)

    def tx_dropped(self, n):
        """Frames node n's eth0 dropped on the way out (a veth counts here what its peer's
        receive backlog refused on a loaded host): sent by ccommd, never on the bridge."""
        out = run(["ip", "-n", self.ns[n], "-j", "-s", "link", "show", "eth0"]).stdout
        return int(json.loads(out)[0]["stats64"]["tx"]["dropped"])

    def host_veth_rx_packets(self, n):
        """Packets the bridge received from node n (its veth's host side): what n sent."""
        i = self.names.index(n)
        with open("/sys/class/net/%sv%d/statistics/rx_packets" % (self.bridge, i)) as f:
            return int(f.read())
