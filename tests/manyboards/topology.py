# SPDX-License-Identifier: Apache-2.0
"""N boards on one Ethernet segment: a network namespace per board (eth0, 10.43.0.ID+1,
MAC 02:63:00:00:00:ID), each joined by a veth pair to port pID of one Linux bridge that
lives in a namespace of its own (PREFIX-sw), so nothing touches the host's namespace.

The bridge snoops IGMP and is its own querier, so UDP multicast reaches only the ports
that joined a group; raw Ethernet multicast (no snooping exists for it) is flooded.
Neighbours are permanent entries (no ARP). nftables counters (bridge prerouting) count
what each board SENDS: ccomm data frames and heartbeats separately (flags bit 0; node
summaries, bit 2, only in the total), for raw (EtherType 0x88B5) and UDP (port 47800) alike.
"""

import json
import os
import re
import subprocess

ETHERTYPE = 0x88B5
UDP_PORT = 47800


def sh(*cmd, check=True, quiet=False):
    cp = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if check and cp.returncode != 0:
        raise RuntimeError("%s: exit %d: %s" % (" ".join(cmd), cp.returncode, cp.stderr.strip()))
    return cp.stdout


def mac_of(i):
    return "02:63:00:00:00:%02x" % i


def ip_of(i):
    return "10.43.0.%d" % (i + 1)


def sweep_stale(prefix_re=r"^mb([0-9]+)-"):
    """Namespaces and segments of an earlier run that was killed outright (pid gone)."""
    for line in sh("ip", "netns", "list", check=False).splitlines():
        name = line.split()[0] if line.split() else ""
        m = re.match(prefix_re, name)
        if m and not os.path.isdir("/proc/%s" % m.group(1)):
            for pid in sh("ip", "netns", "pids", name, check=False).split():
                sh("kill", "-9", pid, check=False)
            sh("ip", "netns", "del", name, check=False)
    for f in os.listdir("/dev/shm"):  # segments of such a run (CCOMM_SHM_PREFIX=/mbPID.)
        m = re.match(r"^mb([0-9]+)\.", f)
        if m and not os.path.isdir("/proc/%s" % m.group(1)):
            os.unlink(os.path.join("/dev/shm", f))


class Topology:
    def __init__(self, prefix, n):
        self.prefix = prefix
        self.n = n
        self.sw = "%s-sw" % prefix
        self.namespaces = []

    def ns(self, i):
        return "%s-%d" % (self.prefix, i)

    def _ns_new(self, name):
        sh("ip", "netns", "add", name)
        self.namespaces.append(name)
        sh("ip", "-n", name, "link", "set", "lo", "up")
        sh("ip", "netns", "exec", name, "sysctl", "-qw", "net.ipv6.conf.all.disable_ipv6=1",
           "net.ipv6.conf.default.disable_ipv6=1")

    def create(self):
        self._ns_new(self.sw)
        sh("ip", "-n", self.sw, "link", "add", "br0", "type", "bridge", "mcast_snooping", "1",
           "mcast_querier", "1", "mcast_igmp_version", "3", "stp_state", "0", "forward_delay", "0")
        sh("ip", "-n", self.sw, "link", "set", "br0", "up")
        for i in range(self.n):
            ns = self.ns(i)
            self._ns_new(ns)
            sh("ip", "link", "add", "eth0", "netns", ns, "address", mac_of(i), "type", "veth",
               "peer", "name", "p%d" % i, "netns", self.sw)
            sh("ip", "-n", self.sw, "link", "set", "p%d" % i, "master", "br0", "up")
            sh("ip", "-n", ns, "addr", "add", ip_of(i) + "/24", "dev", "eth0")
            sh("ip", "-n", ns, "link", "set", "eth0", "up")
            batch = "".join("neigh replace %s lladdr %s dev eth0 nud permanent\n" % (ip_of(j), mac_of(j))
                            for j in range(self.n) if j != i)
            subprocess.run(["ip", "-n", ns, "-batch", "-"], input=batch, text=True, check=True)
        self._counters()

    def _counters(self):
        # Bridge prerouting sees every frame a board sends, forwarded or not. The ccomm
        # frame's flags byte is byte 5 after the EtherType (raw) or after the UDP header.
        rules = []
        for i in range(self.n):
            p = 'iifname "p%d" ' % i
            # data: neither heartbeat (bit 0) nor node summary (bit 2, counted in "a" only)
            rules += [p + 'ether type 0x%x @nh,40,8 & 0x05 == 0x00 counter name "d%d"' % (ETHERTYPE, i),
                      p + 'ether type 0x%x @nh,40,8 & 0x01 == 0x01 counter name "h%d"' % (ETHERTYPE, i),
                      p + 'udp dport %d @th,104,8 & 0x05 == 0x00 counter name "d%d"' % (UDP_PORT, i),
                      p + 'udp dport %d @th,104,8 & 0x01 == 0x01 counter name "h%d"' % (UDP_PORT, i),
                      p + 'counter name "a%d"' % i]
        counters = "".join("  counter %s%d {}\n" % (k, i) for i in range(self.n) for k in "dha")
        text = ("table bridge manyboards {\n%s  chain pre {\n    type filter hook prerouting priority 0; policy accept;\n"
                "%s  }\n}\n" % (counters, "".join("    %s\n" % r for r in rules)))
        cp = subprocess.run(["ip", "netns", "exec", self.sw, "nft", "-f", "-"], input=text, text=True,
                            stderr=subprocess.PIPE)
        if cp.returncode != 0:
            raise RuntimeError("nft: " + cp.stderr.strip())

    def sent_counts(self):
        """{board: {"data": frames, "heartbeat": frames, "all": frames}} each board sent."""
        js = json.loads(sh("ip", "netns", "exec", self.sw, "nft", "-j", "list", "counters"))
        c = {x["counter"]["name"]: x["counter"]["packets"] for x in js["nftables"] if "counter" in x}
        return {i: {"data": c["d%d" % i], "heartbeat": c["h%d" % i], "all": c["a%d" % i]} for i in range(self.n)}

    def destroy(self):
        for ns in reversed(self.namespaces):
            for pid in sh("ip", "netns", "pids", ns, check=False).split():
                sh("kill", "-9", pid, check=False)
            sh("ip", "netns", "del", ns, check=False)
        self.namespaces = []
