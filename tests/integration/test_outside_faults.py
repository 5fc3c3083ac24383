# SPDX-License-Identifier: Apache-2.0
"""Faults a user meets from outside, by the docs (issue 31): each test failed before its fix.

- a stopped (SIGSTOP) ccommd keeps its node: a second one is refused, a killed one's
  successor re-adopts the segment at once;
- a configuration needing more shared memory than the machine gives is refused by
  --check and at start with exit 3 and a one-line cause, leaving no file behind;
- `ccomm pub` reads values as signals.xml does (1e39 and 1e-50 out of range for a float,
  no '+5'), and takes -inf / -nan as values, not options;
- a peer's restart is logged as ccommd(8) says ("peer 'X' restarted (frame seq ...");
- a node summary to a raw node without mac= goes out with dest 0xFFFF (protocol.md);
- one forged frame (no key) stamped an hour ahead makes a peer's genuine values stale for
  one heartbeat interval at most (issue 39; docs/design.md, "Time")."""
import os
import signal
import socket
import struct
import subprocess
import sys
import time
import uuid

import sys

from harness import BIN, SANITIZED, NodePair, run, wait_for

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import wire_vectors  # noqa: E402  (independent encoder of the wire format)

PAIR_UDP = """<?xml version="1.0" encoding="UTF-8"?>
<ccomm version="1">
  <network udp_port="47841" heartbeat_ms="50" peer_timeout_ms="1000"/>
  <node name="control" ip="10.42.0.1" transport="udp"/>
  <node name="planner" ip="10.42.0.2" transport="udp"/>
  <signal name="gain" type="float" producer="control" consumers="planner"/>
  <signal name="speed" type="double" producer="control" consumers="planner"/>
  <signal name="mode" type="int32" producer="control" consumers="planner"/>
</ccomm>
"""


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_stopped_ccommd_keeps_its_node_and_a_killed_one_is_readopted(tmp_path):
    with NodePair(config=write(tmp_path, "pair.xml", PAIR_UDP)) as pair:
        pair.start("control")
        pair.start("planner")
        first = pair.daemons["planner"]
        os.kill(first.pid, signal.SIGSTOP)
        t0 = time.time()
        try:
            second = subprocess.Popen(pair.exec_prefix("planner") + [os.path.join(BIN, "ccommd"), "--node", "planner",
                                      "--no-rt", "-c", pair.config], env=pair.env, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, text=True)
            try:
                out, _ = second.communicate(timeout=20)
            except subprocess.TimeoutExpired:
                second.kill()
                out, _ = second.communicate()
                raise AssertionError("a second ccommd took over a stopped one's node: " + out[-1500:])
        finally:
            took = time.time() - t0
            os.kill(first.pid, signal.SIGCONT)
        print("\nfigure: second ccommd next to a stopped one refused in %.0f ms, exit %s" % (took * 1000, second.returncode))
        assert second.returncode == 3, out
        assert "already running (pid %d" % first.pid in out, out
        assert first.poll() is None
        # A killed ccommd holds nothing: the next one starts at once and re-adopts.
        assert pair.stop("planner", signal.SIGKILL) == -signal.SIGKILL
        t0 = time.time()
        pair.start("planner")
        print("figure: after SIGKILL the next ccommd was serving in %.0f ms" % ((time.time() - t0) * 1000))
        assert wait_for(lambda: "re-adopted" in pair.log("planner"), 10), pair.log("planner")


def big_config(tmp_path):
    # 64 event signals of 64 KiB with queue_depth 1024: a valid file needing 4.3 GB.
    sigs = "".join('  <signal name="blob%02d" kind="event" type="double" count="8192" queue_depth="1024" '
                   'producer="solo"/>\n' % i for i in range(64))
    return write(tmp_path, "big.xml", '<?xml version="1.0"?>\n<ccomm version="1">\n'
                 '  <node name="solo" ip="127.0.0.1" transport="udp"/>\n%s</ccomm>\n' % sigs)


def in_small_shm(cmd, size="256m", limit_as=None):
    """Runs cmd in a mount namespace whose /dev/shm is a fresh tmpfs of `size`; returns
    (exit status, output, what is left in that /dev/shm)."""
    prlimit = "prlimit --as=%d " % limit_as if limit_as else ""
    script = ("mount -t tmpfs -o size=%s tmpfs /dev/shm && %s%s; rc=$?; echo; echo LEFT: $(ls /dev/shm); exit $rc"
              % (size, prlimit, " ".join(cmd)))
    p = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script], capture_output=True,
                       text=True, timeout=120)
    return p.returncode, p.stdout + p.stderr, p.stdout.rsplit("LEFT:", 1)[1].strip()


def test_segment_too_big_for_the_machine_is_refused_with_exit_3(tmp_path):
    cfg = big_config(tmp_path)
    ccommd = os.path.join(BIN, "ccommd")
    rc, out, _ = in_small_shm([ccommd, "--check", cfg])
    assert rc == 3 and "needs a 4.3 GB shared-memory segment" in out and "/dev/shm has" in out, out
    rc, out, left = in_small_shm([ccommd, "--no-rt", "-n", "solo", "-c", cfg])
    assert rc == 3 and "needs a 4.3 GB" in out and "/dev/shm has" in out, out
    assert left.split() == ["ccomm.solo.lock"], "left in /dev/shm: " + left  # the lock is tiny and stays
    # Room in /dev/shm, but an address-space limit of 1 GB (as a memory limit would). A
    # sanitizer's shadow memory alone needs more address space than that.
    if SANITIZED:
        return
    rc, out, left = in_small_shm([ccommd, "--no-rt", "-n", "solo", "-c", cfg], size="16g", limit_as=1 << 30)
    assert rc == 3 and "RLIMIT_AS" in out, out
    assert left.split() == ["ccomm.solo.lock"], left


def test_pub_reads_values_as_signals_xml_does(tmp_path):
    with NodePair(config=write(tmp_path, "pair.xml", PAIR_UDP)) as pair:
        pair.start("control")
        for sig, word in (("gain", "1e39"), ("gain", "1e-50"), ("mode", "+5"), ("speed", "+1.5")):
            r = pair.cli("control", "pub", sig, word, check=False)
            assert r.returncode != 0 and ("out of range" in r.stderr or "not a valid" in r.stderr), (word, r.stderr)
        for sig, word, shown in (("speed", "-inf", "-inf"), ("gain", "-1e-3", "-0.001"), ("mode", "-0x10", "-16")):
            r = pair.cli("control", "pub", sig, word, check=False)
            assert r.returncode == 0, (word, r.stderr)
            out = pair.cli("control", "echo", sig, "--once").stdout.split()
            assert out[1] == shown, (word, out)
        r = pair.cli("control", "pub", "speed", "-nan", check=False)
        assert r.returncode == 0 and "unknown option" not in r.stderr, r.stderr


def test_peer_restart_is_logged_as_documented(tmp_path):
    with NodePair(config=write(tmp_path, "pair.xml", PAIR_UDP)) as pair:
        pair.start("control")
        pair.start("planner")
        assert wait_for(lambda: "peer 'control' up" in pair.log("planner"), 10), pair.log("planner")
        time.sleep(0.3)  # some frames, so the restarted sequence goes back
        assert pair.stop("control") == 0
        pair.start("control")
        assert wait_for(lambda: "peer 'control' restarted (frame seq " in pair.log("planner"), 10), pair.log("planner")
        assert "frame sequence resynchronised" not in pair.log("planner")


def test_summary_to_a_raw_node_without_mac_goes_to_every_station():
    # dist/signals.xml: raw, no mac=, summaries every 1000 ms. Capture what reaches planner.
    with NodePair() as pair:
        pair.start("control")
        code = ("import socket,struct,sys,time\n"
                "s=socket.socket(socket.AF_PACKET,socket.SOCK_RAW,socket.htons(0x88B5));s.bind(('eth0',0))\n"
                "s.settimeout(0.2);end=time.time()+15\n"
                "while time.time()<end:\n"
                "  try: f=s.recv(2048)[14:]\n"
                "  except socket.timeout: continue\n"
                "  if f[:4]==b'CCMW' and f[5]&4 and struct.unpack('>H',f[6:8])[0]==0:\n"
                "    print(struct.unpack('>H',f[28:30])[0]); sys.exit(0)\n"
                "sys.exit(1)\n")
        r = run(pair.exec_prefix("planner") + [sys.executable, "-c", code], check=False, timeout=30)
        assert r.returncode == 0, "no summary from control: " + r.stderr
        assert int(r.stdout) == 0xFFFF, "summary dest %s" % r.stdout


def foreign(pair, node):
    return pair.stats(node)["counters"]["frames_foreign"]


def test_ethertype_mismatch_is_logged_and_counted(tmp_path):
    """control on EtherType 0x88B5, planner on 0x88B6: neither hears the other; both say why."""
    with NodePair() as pair:
        pair.start("control")
        other = open(pair.config).read().replace('ethertype="0x88B5"', 'ethertype="0x88B6"')
        assert 'ethertype="0x88B6"' in other
        pair.config = write(tmp_path, "other.xml", other)
        pair.start("planner")
        assert wait_for(lambda: foreign(pair, "planner") > 0 and foreign(pair, "control") > 0, 10), \
            (pair.stats("planner")["counters"], pair.log("planner"))
        assert wait_for(lambda: "raw, EtherType 0x88B5" in pair.log("planner"), 5), pair.log("planner")
        assert "it uses raw, EtherType 0x88B6" in pair.log("planner"), pair.log("planner")
        assert "raw, EtherType 0x88B6" in pair.log("control"), pair.log("control")


def test_transport_mismatch_is_logged_and_counted(tmp_path):
    """control raw, planner UDP (--transport udp): each counts the other's frames as foreign."""
    with NodePair() as pair:
        pair.start("control")
        pair.start("planner", extra=["--transport", "udp"])
        assert wait_for(lambda: foreign(pair, "planner") > 0 and foreign(pair, "control") > 0, 10), \
            (pair.stats("planner")["counters"], pair.stats("control")["counters"])
        assert wait_for(lambda: "raw, EtherType 0x88B5" in pair.log("planner"), 5), pair.log("planner")
        assert "over UDP to port 47800 from 10.42.0.2" in pair.log("control"), pair.log("control")
        # A matched pair counts nothing.
    with NodePair() as pair:
        pair.start("control")
        pair.start("planner")
        assert wait_for(lambda: pair.stats("planner")["peers"][0]["alive"], 10)
        time.sleep(0.5)
        assert foreign(pair, "planner") == 0 and foreign(pair, "control") == 0


def test_a_forged_future_stamp_makes_genuine_values_stale_one_heartbeat_interval_at_most(tmp_path):
    """A frame "from control" (its address, the config's hash, no key needed) stamped an hour
    ahead: planner read control's genuine values stale, with an age of the host's uptime, for
    2-4 s (the offset floor's window). Now past one heartbeat interval (50 ms here) they are
    fresh again."""
    config = PAIR_UDP.replace('name="speed" type="double"', 'name="speed" type="double" stale_after_ms="100"')
    with NodePair(config=write(tmp_path, "pair.xml", config)) as pair:
        pair.start("control")
        pair.start("planner")
        assert wait_for(lambda: "peer 'control' up" in pair.log("planner"), 10), pair.log("planner")
        pair.spawn("control", "pub", "speed", "1.5", "--rate", "200", "--count", "100000")
        assert wait_for(lambda: pair.echo_once("planner", "speed")[1] == "fresh", 10)
        config_hash = int(pair.log("planner").split("config hash ")[1].split()[0], 16)
        now = time.monotonic_ns()  # one host: the namespaces share CLOCK_MONOTONIC
        forged = wire_vectors.Frame("forged", "ok", sender=0, dest=1, config_hash=config_hash, seq=1,
                                    time_ns=now + 3600 * 10**9,
                                    entries=[wire_vectors.Entry(2, "int32", [7], seq=1, time_ns=now)]).data()
        code = ("import socket,sys; s=socket.socket(socket.AF_INET,socket.SOCK_DGRAM); s.bind(('10.42.0.1',0)); "
                "s.sendto(bytes.fromhex(sys.argv[1]),('10.42.0.2',47841))")
        rx0 = pair.stats("planner")["counters"]["frames_rx"]
        run(pair.exec_prefix("control") + [sys.executable, "-c", code, forged.hex()])
        t_forged = time.monotonic()
        assert wait_for(lambda: pair.stats("planner")["counters"]["frames_rx"] > rx0, 5)
        time.sleep(0.2)  # past one heartbeat interval (50 ms) and a CLI run
        stale = []
        while time.monotonic() - t_forged < 3.0:  # the old floor's window was 2-4 s
            value, status = pair.echo_once("planner", "speed")
            if status != "fresh":
                stale.append("%s %s at %.0f ms" % (value, status, (time.monotonic() - t_forged) * 1000))
        assert not stale, "control's genuine speed read after the forged frame: %s" % stale[:5]
