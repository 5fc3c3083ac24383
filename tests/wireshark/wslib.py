# SPDX-License-Identifier: Apache-2.0
"""Shared helpers of the Wireshark dissector tests: pcap writing in both encapsulations
of docs/protocol.md ("Transport encapsulation"), and running tshark with the dissector
in an isolated configuration (no user preferences or personal plugins leak in)."""
import json
import os
import shutil
import struct
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
# CCOMM_DISSECTOR: test another copy (an installed one, or a deliberately broken one)
DISSECTOR = os.environ.get("CCOMM_DISSECTOR") or os.path.join(ROOT, "integrations", "wireshark", "ccomm.lua")

ETHERTYPE = 0x88B5
UDP_PORT = 47800
MAC_A = bytes.fromhex("020000000001")
MAC_B = bytes.fromhex("020000000002")
IP_A, IP_B = bytes([10, 42, 0, 1]), bytes([10, 42, 0, 2])
BASE_TIME = 1700000000  # fixed capture times: the goldens must not depend on the clock


def ethernet(frame, ethertype=ETHERTYPE):
    """Raw ccomm: MACs, EtherType, the frame. No padding added (as captured on veth)."""
    return MAC_B + MAC_A + struct.pack(">H", ethertype) + frame


def _checksum(data):
    if len(data) % 2:
        data += b"\0"
    s = sum(struct.unpack(">%dH" % (len(data) // 2), data))
    while s >> 16:
        s = (s & 0xFFFF) + (s >> 16)
    return ~s & 0xFFFF


def udp(frame, port=UDP_PORT):
    """ccomm over UDP/IPv4 in Ethernet, with correct IPv4 and UDP checksums."""
    udp_len = 8 + len(frame)
    pseudo = IP_A + IP_B + struct.pack(">BBH", 0, 17, udp_len)
    head = struct.pack(">HHHH", port, port, udp_len, 0)
    csum = _checksum(pseudo + head + frame) or 0xFFFF
    head = struct.pack(">HHHH", port, port, udp_len, csum)
    ip = struct.pack(">BBHHHBBH4s4s", 0x45, 0, 20 + udp_len, 0, 0x4000, 64, 17, 0, IP_A, IP_B)
    ip = ip[:10] + struct.pack(">H", _checksum(ip)) + ip[12:]
    return MAC_B + MAC_A + b"\x08\x00" + ip + head + frame


def write_pcap(path, packets, snaplens=None):
    """Classic pcap, link type Ethernet, one second between packets. snaplens[i], when
    given and shorter, cuts packet i as a capture with that snap length would."""
    with open(path, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1))
        for i, p in enumerate(packets):
            cap = min(len(p), snaplens[i]) if snaplens else len(p)
            f.write(struct.pack("<IIII", BASE_TIME + i, 0, cap, len(p)))
            f.write(p[:cap])


class Tshark:
    """tshark with ccomm.lua loaded, HOME and configuration in a private directory."""

    def __init__(self, workdir, dissector=DISSECTOR):
        self.tshark = shutil.which("tshark")
        if not self.tshark:
            raise RuntimeError("tshark not found (Debian: apt-get install tshark; scripts/setup wireshark)")
        self.home = tempfile.mkdtemp(prefix="home-", dir=workdir)
        os.chmod(self.home, 0o755)
        os.chmod(workdir, 0o755)
        # a copy: the checkout may not be readable by the user tshark falls back to
        self.dissector = self.readable(dissector)
        self.env = dict(os.environ, HOME=self.home, XDG_CONFIG_HOME=os.path.join(self.home, ".config"),
                        WIRESHARK_CONFIG_DIR=os.path.join(self.home, "wireshark"), TZ="UTC", LC_ALL="C.UTF-8")
        self.prefix = []
        # As root, Wireshark runs Lua scripts given with -X lua_script only when the global
        # init.lua sets run_user_scripts_when_superuser (Debian 12: true). If it does not,
        # run tshark as nobody instead (files we give it are made world-readable).
        if not self._loaded() and os.geteuid() == 0 and shutil.which("setpriv"):
            self.prefix = ["setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups"]
            self.how = "as nobody (init.lua disables Lua scripts for root)"
            if not self._loaded():
                raise RuntimeError("tshark does not load %s, not even as nobody" % dissector)
        elif not self._loaded():
            raise RuntimeError("tshark does not load %s (is Lua enabled in init.lua?)" % dissector)
        else:
            self.how = "as uid %d" % os.geteuid()

    def _loaded(self):
        r = self.run(["-G", "protocols"], check=False, first=True)
        return any(line.split("\t")[-1:] == ["ccomm"] for line in r.stdout.splitlines())

    def run(self, args, check=True, timeout=120, first=False):
        load = ["-X", "lua_script:" + self.dissector]
        # -G must come first on tshark's command line
        cmd = self.prefix + [self.tshark] + (list(args) + load if first else load + list(args))
        r = subprocess.run(cmd, capture_output=True, text=True, env=self.env, timeout=timeout,
                           errors="replace", cwd=self.home)
        if check and r.returncode != 0:
            raise RuntimeError("%s: exit %d\n%s" % (" ".join(cmd), r.returncode, r.stderr))
        return r

    def readable(self, path):
        """path, readable by every user (files from elsewhere are copied into HOME)."""
        workdir = os.path.dirname(self.home)
        if not os.path.abspath(path).startswith(workdir + os.sep):
            copy = os.path.join(self.home, os.path.basename(path))
            shutil.copyfile(path, copy)
            path = copy
        os.chmod(path, 0o644)
        return path

    def config(self, xml_path):
        """The -o option loading `xml_path` into the dissector: the configuration as ccommd
        resolves it (`ccommd --check XML --json`, $CCOMM_BUILD_DIR/bin/ccommd), in HOME."""
        ccommd = os.path.join(os.environ["CCOMM_BUILD_DIR"], "bin", "ccommd")
        r = subprocess.run([ccommd, "--check", xml_path, "--json"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("ccommd --check %s --json: %s" % (xml_path, r.stderr))
        out = os.path.join(self.home, os.path.basename(xml_path) + ".json")
        with open(out, "w") as f:
            f.write(r.stdout)
        return "ccomm.config:" + self.readable(out)

    def fields(self, pcap, names, extra=()):
        """One dict per packet: field -> list of values (tshark -T json -e)."""
        args = ["-r", self.readable(pcap), "-T", "json"] + list(extra)
        for n in names:
            args += ["-e", n]
        r = self.run(args)
        out = []
        for pkt in json.loads(r.stdout or "[]"):
            out.append(pkt["_source"]["layers"])
        return out, r.stderr
