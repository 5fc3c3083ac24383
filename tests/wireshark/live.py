#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The dissector on a capture of the demo: two ccommd (dist/signals.xml, the thesis
set-up simulation) in two network namespaces joined by a veth pair, raw Ethernet and
then UDP; ccomm-latency writes all 36 + 9 doubles at 1 kHz on both sides for a second
while dumpcap captures the control node's eth0.

  live.py WORKDIR [--seconds S]        (root: namespaces, raw sockets; exit 4 otherwise)

Checks per transport: every ccomm frame decodes without an error or warning, with the
signals.xml loaded (so config_hash matches the file and every entry matches its signal:
producer, type, count, kind); each node's entries name exactly the signals it produces
(from `ccommd --check --json` here: the dissector only names what it is given); the frames use the expected
encapsulation; frame sequence numbers per (sender, dest) are contiguous (the capture is
complete and seq is decoded right); and the capture holds at least every frame the
daemons counted as sent (ccomm stats frames_tx) while ccomm-latency ran.
"""
import argparse
import glob
import json
import os
import signal
import subprocess
import sys
import time

import wslib

CONFIG = os.path.join(wslib.ROOT, "dist", "signals.xml")
failures = []


def check(ok, msg):
    print(("ok - " if ok else "not ok - ") + msg)
    if not ok:
        failures.append(msg)


def import_harness():
    """The integration tests' two-node harness (NodePair), wherever the tree keeps it."""
    for path in sorted(glob.glob(os.path.join(wslib.ROOT, "**", "harness.py"), recursive=True)):
        if "class NodePair" in open(path, encoding="utf-8").read():
            sys.path.insert(0, os.path.dirname(path))
            import harness
            return harness
    raise RuntimeError("no harness.py with NodePair in the tree")


def resolved(bin_dir):
    """The configuration as ccommd resolves it (`ccommd --check --json`)."""
    r = subprocess.run([os.path.join(bin_dir, "ccommd"), "--check", CONFIG, "--json"], capture_output=True,
                       text=True, check=True)
    return json.loads(r.stdout)


def producers(cfg):
    """signal id -> (name, producer node id, type, count, kind)."""
    nodes = [n["name"] for n in cfg["nodes"]]
    out = {s["id"]: (s["name"], nodes.index(s["producer"]), s["type"], s["count"], s["kind"])
           for s in cfg["signals"]}
    return nodes, out


def frames_tx(stats):
    return {p["name"]: p["frames_tx"] for p in stats["peers"]}


def capture(harness, transport, seconds, work, ts):
    pcap = os.path.join(work, "demo-%s.pcapng" % transport)
    with harness.NodePair(transport="udp" if transport == "udp" else None) as pair:
        for node in ("control", "planner"):
            pair.start(node)
        dumpcap = subprocess.Popen(pair.exec_prefix("control") + ["dumpcap", "-q", "-i", "eth0", "-w", pcap],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 10
        while time.time() < deadline and not (os.path.exists(pcap) and os.path.getsize(pcap) > 0):
            time.sleep(0.05)
        time.sleep(0.3)  # dumpcap writes the file header just before it starts capturing
        before = {n: frames_tx(pair.stats(n)) for n in ("control", "planner")}
        apps = [pair.spawn(n, "--rate", "1000", "--duration", str(seconds), "--warmup", "0", tool="ccomm-latency")
                for n in ("planner", "control")]
        for app in apps:
            app.wait(timeout=seconds + 30)
        after = {n: frames_tx(pair.stats(n)) for n in ("control", "planner")}
        time.sleep(0.3)
        dumpcap.send_signal(signal.SIGINT)
        try:
            _, err = dumpcap.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            dumpcap.kill()
            _, err = dumpcap.communicate()
        if not os.path.exists(pcap):
            raise RuntimeError("dumpcap wrote nothing: %s" % err)
    sent = {(n, peer): after[n][peer] - before[n][peer] for n in after for peer in after[n]}
    return pcap, sent


def analyse(ts, pcap, transport, sent, nodes, signals, want_hash):
    fields = ["ccomm.sender", "ccomm.dest", "ccomm.seq", "ccomm.flags.heartbeat", "ccomm.flags.summary",
              "ccomm.config_hash",
              "ccomm.entry.signal", "ccomm.entry.type", "ccomm.entry.count", "ccomm.entry.flags",
              "ccomm.decode_error", "_ws.expert.message", "_ws.expert.severity", "_ws.lua.text",
              "eth.type", "udp.dstport"]
    pkts, _ = ts.fields(pcap, fields, ["-o", ts.config(CONFIG), "-Y", "ccomm"])
    types = {"double": "6", "float": "5", "int64": "4", "uint32": "3", "int32": "2", "bool": "1"}
    bad, seqs, data, entries, encaps = [], {}, {}, {}, set()
    for p in pkts:
        sender, dest, seq = int(p["ccomm.sender"][0]), int(p["ccomm.dest"][0]), int(p["ccomm.seq"][0])
        sev = [int(s) for s in p.get("_ws.expert.severity", [])]
        if "ccomm.decode_error" in p or "_ws.lua.text" in p or any(s >= 0x00600000 for s in sev):
            bad.append("%s seq %d: %s %s" % (sender, seq, p.get("ccomm.decode_error"), p.get("_ws.expert.message")))
        if p["ccomm.config_hash"][0] != "0x" + want_hash:
            bad.append("config_hash %s" % p["ccomm.config_hash"][0])
        encaps.add("udp %s" % p["udp.dstport"][0] if "udp.dstport" in p else "eth %s" % p.get("eth.type", ["?"])[0])
        # node summaries have a frame sequence of their own (protocol.md, "Node summary")
        summary = p.get("ccomm.flags.summary", ["0"])[0] in ("1", "True")
        seqs.setdefault((sender, dest, summary), []).append(seq)
        if not summary and p["ccomm.flags.heartbeat"][0] not in ("1", "True"):
            data[sender] = data.get(sender, 0) + 1
        for sid, typ, cnt, fl in zip(p.get("ccomm.entry.signal", []), p.get("ccomm.entry.type", []),
                                     p.get("ccomm.entry.count", []), p.get("ccomm.entry.flags", [])):
            entries.setdefault(sender, set()).add(int(sid))
            name, producer, tname, count, kind = signals.get(int(sid), ("?", -1, "?", 0, "?"))
            if (producer, types.get(tname), count, kind) != (sender, typ, int(cnt), "event" if int(fl, 0) & 1 else "state"):
                bad.append("entry signal %s from node %d: type %s count %s flags %s, signals.xml: %s"
                           % (sid, sender, typ, cnt, fl, signals.get(int(sid))))
    n = len(pkts)
    check(n > 0 and not bad, "%s: %d ccomm frames decode with no error or warning, config_hash 0x%s, every "
          "entry matches signals.xml%s" % (transport, n, want_hash, "" if not bad else ": " + "; ".join(bad[:5])))
    want_encap = {"udp %d" % wslib.UDP_PORT} if transport == "udp" else {"eth 0x%04x" % wslib.ETHERTYPE}
    check(encaps == want_encap, "%s: encapsulation %s" % (transport, sorted(encaps)))
    for node_id, node in enumerate(nodes):
        want = {sid for sid, s in signals.items() if s[1] == node_id}
        check(entries.get(node_id) == want and data.get(node_id, 0) >= 100,
              "%s: %s sent %d data frames carrying signals %s (produces %d signals)"
              % (transport, node, data.get(node_id, 0), span(entries.get(node_id, set())), len(want)))
    gaps = {k: [b for a, b in zip(sorted(v), sorted(v)[1:]) if b != a + 1] for k, v in seqs.items()}
    check(all(not g for g in gaps.values()), "%s: frame seq contiguous per (sender, dest) %s"
          % (transport, {"%d->%d%s" % (k[0], k[1], " summary" if k[2] else ""): "%d..%d" % (min(v), max(v))
                         for k, v in seqs.items()}))
    for (node, peer), count in sorted(sent.items()):
        got = sum(len(v) for (s, d, summ), v in seqs.items() if s == nodes.index(node) and not summ)
        check(got >= count, "%s: %s -> %s: %d frames captured, daemon counted %d sent while the apps ran"
              % (transport, node, peer, got, count))


def span(ids):
    return "%d..%d" % (min(ids), max(ids)) if ids else "none"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("workdir")
    ap.add_argument("--seconds", type=float, default=1.0)
    args = ap.parse_args()
    if os.geteuid() != 0:
        print("# SKIP live capture: needs root (network namespaces, raw sockets, capture)")
        return 4
    harness = import_harness()
    for tool in ("ccommd", "ccomm", "ccomm-latency"):
        if not os.access(os.path.join(harness.BIN, tool), os.X_OK):
            print("Bail out! %s missing in %s (build first, set CCOMM_BUILD_DIR)" % (tool, harness.BIN))
            return 1
    ts = wslib.Tshark(args.workdir)
    cfg = resolved(harness.BIN)
    nodes, signals = producers(cfg)
    want_hash = cfg["hash"]
    for transport in ("raw", "udp"):
        pcap, sent = capture(harness, transport, args.seconds, args.workdir, ts)
        analyse(ts, pcap, transport, sent, nodes, signals, want_hash)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
