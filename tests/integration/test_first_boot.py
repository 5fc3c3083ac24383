# SPDX-License-Identifier: Apache-2.0
"""A board's first boot from one image and one signals.xml (issue 41), in a private
network and UTS namespace (unshare: a veth eth0 with a board's MAC, the hostname the
image has): ccommd --board-net finds the node by MAC, sets the hostname, brings eth0 up
with the node's address; ccommd's fatal errors carry syslog priority 3 under journald;
ccommd's wait for its node ends when the hostname names one."""
import os
import re
import subprocess
import tempfile
import textwrap
import time

from harness import BIN

CCOMMD = os.path.join(BIN, "ccommd")

CONFIG = """<?xml version="1.0" encoding="UTF-8"?>
<ccomm version="1">
  <network ethertype="0x88B5" udp_port="{port}" heartbeat_ms="100" peer_timeout_ms="300"/>
  <node name="control" interface="eth0" ip="{ip1}" mac="52:54:00:42:00:01" transport="{transport}"/>
  <node name="planner" interface="eth0" {ip2} mac="52:54:00:42:00:02" transport="{transport}"/>
  <signal name="pos" type="double" producer="control" consumers="planner"/>
  <signal name="sp" type="double" producer="planner" consumers="control"/>
</ccomm>
"""


def write(d, name, text):
    path = os.path.join(d, name)
    with open(path, "w") as f:
        f.write(text)
    return path


# systemd's JOURNAL_STREAM: the "device:inode" of the stream stderr is on (ccommd compares it
# with its stderr; an inherited variable whose stream is not stderr any more means no journal).
AS_JOURNAL = "export JOURNAL_STREAM=$(stat -L -c %d:%i /proc/self/fd/2)\n"


def in_namespace(script, timeout=40, env=None, journal=False):
    """Runs a bash script in new network + UTS namespaces (hostname 'localhost'); journal:
    its stderr stands for the journal's stream (JOURNAL_STREAM names it)."""
    full = "set -e\nhostname localhost\n" + (AS_JOURNAL if journal else "") + textwrap.dedent(script)
    return subprocess.run(["unshare", "--net", "--uts", "bash", "-c", full], capture_output=True, text=True,
                          timeout=timeout, env=env)


def run_as_journal(cmd, timeout=20):
    """Runs cmd with stderr on a pipe that JOURNAL_STREAM names, as systemd's journal stream."""
    r, w = os.pipe()
    st = os.fstat(w)
    env = dict(os.environ, JOURNAL_STREAM="%d:%d" % (st.st_dev, st.st_ino))
    with os.fdopen(r) as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=w, env=env, text=True)
        os.close(w)
        text = err.read()
        proc.wait(timeout=timeout)
    return subprocess.CompletedProcess(cmd, proc.returncode, "", text)


def test_board_net_by_mac_sets_hostname_link_and_address():
    with tempfile.TemporaryDirectory() as d:
        cfg = write(d, "signals.xml", CONFIG.format(port=47890, ip1="10.42.0.1", ip2='ip="10.42.0.2"', transport="raw"))
        netdir = os.path.join(d, "network")
        r = in_namespace(f"""
            ip link add eth0 type veth peer name veth1
            ip link set eth0 address 52:54:00:42:00:02
            ip link show eth0 | grep -q 'state DOWN'
            {CCOMMD} --config {cfg} --board-net --network-dir {netdir}
            echo "HOST $(hostname)"
            ip -o link show eth0 | grep -q '<.*UP.*>' && echo LINKUP
            ip -o -4 addr show eth0 | awk '{{print "ADDR", $4}}'
            """)
        assert r.returncode == 0, r.stdout + r.stderr
        assert "this board is node 'planner' (planner by mac 52:54:00:42:00:02 on eth0)" in r.stderr, r.stderr
        assert "HOST planner" in r.stdout, r.stdout
        assert "LINKUP" in r.stdout, r.stdout
        assert "ADDR 10.42.0.2/24" in r.stdout, r.stdout
        with open(os.path.join(netdir, "10-ccomm-board.network")) as f:
            net = f.read()
        assert "Name=eth0\n" in net and "Address=10.42.0.2/24\n" in net, net


def test_board_net_kernel_cmdline_wins_and_no_ip_means_dhcp():
    # /proc/cmdline of this namespace: a file bound over it (own mount namespace).
    with tempfile.TemporaryDirectory() as d:
        cfg = write(d, "signals.xml", CONFIG.format(port=47891, ip1="10.42.0.1", ip2="", transport="raw"))
        cmdline = write(d, "cmdline", "console=ttyAMA0 net.ifnames=0 ccomm.node=planner root=/dev/vda rw\n")
        r = subprocess.run(["unshare", "--mount", "--propagation", "private", "--net", "--uts", "bash", "-c", f"""
            set -e
            hostname localhost
            mount --bind {cmdline} /proc/cmdline
            ip link add eth0 type veth peer name veth1
            ip link set eth0 address 52:54:00:42:00:01
            {CCOMMD} --config {cfg} --board-net --dry-run
            echo "HOST $(hostname)"
            {CCOMMD} --config {cfg} --board-net --dry-run --node control >/dev/null
            """], capture_output=True, text=True, timeout=40)
        assert r.returncode == 0, r.stdout + r.stderr
        # ccomm.node= beats the MAC (control's); the node has no ip=: DHCP.
        assert ("this board is node 'planner' (ccomm.node= on the kernel command line): hostname planner, "
                "interface eth0, DHCP") in r.stderr, r.stderr
        assert "DHCP=ipv4" in r.stdout and "Address=" not in r.stdout, r.stdout
        assert "HOST localhost" in r.stdout, "--dry-run changed the hostname: " + r.stdout
        # --node (or CCOMM_NODE, /etc/default/ccommd) beats the command line.
        assert "this board is node 'control' (--node)" in r.stderr, r.stderr


def test_board_net_no_node_is_an_error_at_priority_3():
    with tempfile.TemporaryDirectory() as d:
        cfg = write(d, "signals.xml", CONFIG.format(port=47892, ip1="10.42.0.1", ip2='ip="10.42.0.2"', transport="raw"))
        t0 = time.monotonic()
        r = in_namespace(journal=True, script=f"""
            ip link add eth0 type veth peer name veth1
            ip link set eth0 address 02:00:00:00:00:09
            CCOMM_BOARD_NET_WAIT_S=4 {CCOMMD} --config {cfg} --board-net --network-dir {d}/n || echo "EXIT $?"
            echo "HOST $(hostname)"
            """)
        took = time.monotonic() - t0
        assert "EXIT 1" in r.stdout, r.stdout + r.stderr
        assert "HOST localhost" in r.stdout, r.stdout
        assert re.search(r"^<3>ccommd --board-net: no node of .* the hostname 'localhost' names none", r.stderr, re.M), r.stderr
        assert 3.9 <= took < 14, f"waited {took:.1f} s for the interfaces (CCOMM_BOARD_NET_WAIT_S=4)"
        assert "waiting up to 4 s" in r.stderr, r.stderr


def test_fatal_config_errors_carry_priority_3():
    """journalctl -p err must show why ccommd failed: every FILE:LINE line gets "<3>"."""
    with tempfile.TemporaryDirectory() as d:
        bad = write(d, "bad.xml", CONFIG.format(port=47893, ip1="10.42.0.1", ip2='ip="10.42.0.2"', transport="raw")
                    .replace('type="double" producer="planner"', 'type="dubble" producer="planner"')
                    .replace('producer="control" consumers', 'producer="nobody" consumers'))
        r = run_as_journal([CCOMMD, "--config", bad, "--no-rt"])
        assert r.returncode == 1, r.stderr
        lines = [l for l in r.stderr.splitlines() if l.strip()]
        located = [l for l in lines if re.match(r"^<3>" + re.escape(bad) + r":\d+:", l)]
        assert len(located) >= 2, "FILE:LINE errors without <3>:\n" + r.stderr
        assert all(l.startswith("<") for l in lines), "a line without a priority prefix:\n" + r.stderr
        # A usage error (a bad CCOMMD_OPTS) too, not getopt's unprefixed message.
        r = run_as_journal([CCOMMD, "--config", bad, "--no-such-option"])
        assert r.returncode == 2, r.stderr
        assert r.stderr.startswith("<3>ccommd: unknown option or missing argument: '--no-such-option'"), r.stderr
        # Without journald (a terminal) the lines stay as they were, no prefix; also when the
        # variable was inherited but stderr is another stream now (ccommd run from a unit's script).
        for env in ({k: v for k, v in os.environ.items() if k != "JOURNAL_STREAM"},
                    dict(os.environ, JOURNAL_STREAM="8:1234")):
            r = subprocess.run([CCOMMD, "--check", bad], capture_output=True, text=True, timeout=20, env=env)
            assert r.returncode == 1 and re.search("^" + re.escape(bad) + r":\d+:", r.stderr, re.M), r.stderr


def test_no_node_error_priority_3_and_the_wait_ends_on_the_hostname():
    """ccommd waits up to 10 s for its node; a hostname set meanwhile (ccomm-board-net
    running late) ends the wait within a poll, not at the 10 s limit; no node at all is a
    priority-3 error."""
    with tempfile.TemporaryDirectory() as d:
        cfg = write(d, "signals.xml", CONFIG.format(port=47894, ip1="127.0.0.1", ip2='ip="127.0.0.2"', transport="udp")
                    .replace(' mac="52:54:00:42:00:01"', "").replace(' mac="52:54:00:42:00:02"', ""))
        env = dict(os.environ, CCOMM_SHM_PREFIX=f"/ccq-fb{os.getpid()}.")
        env.pop("CCOMM_NODE", None)
        r = in_namespace(f"""
            ip link set lo up
            touch {d}/log
            JOURNAL_STREAM=$(stat -c %d:%i {d}/log) {CCOMMD} --config {cfg} --no-rt --ptp-socket none 2>{d}/log &
            pid=$!
            sleep 1.5
            hostname planner
            t=$(date +%s%N)
            for i in $(seq 100); do grep -q "this board is node 'planner'" {d}/log && break; sleep 0.05; done
            echo "FOUND_MS $(( ($(date +%s%N) - t) / 1000000 ))"
            kill -0 $pid && echo RUNNING
            kill -TERM $pid; wait $pid || true
            cat {d}/log >&2
            hostname localhost
            {CCOMMD} --config {cfg} --no-rt --ptp-socket none || echo "EXIT $?"
            """, env=env, timeout=60, journal=True)
        assert "RUNNING" in r.stdout, r.stdout + r.stderr
        found_ms = int(re.search(r"FOUND_MS (\d+)", r.stdout).group(1))
        assert found_ms < 1000, f"ccommd saw the hostname {found_ms} ms after it was set\n" + r.stderr
        assert "EXIT 1" in r.stdout, r.stdout + r.stderr
        assert re.search(r"^<3>ccommd: no node of .* is this board: the hostname 'localhost' names none", r.stderr,
                         re.M), r.stderr
        for seg in os.listdir("/dev/shm"):
            if seg.startswith(f"ccq-fb{os.getpid()}."):
                os.unlink(os.path.join("/dev/shm", seg))


def test_a_long_fatal_error_is_whole():
    """A "no node" message naming 64 nodes is longer than a log line buffer: it must reach
    the journal whole (its advice is at the end), with its priority."""
    with tempfile.TemporaryDirectory() as d:
        nodes = "\n".join(f'  <node name="a_rather_long_node_name_{i:02d}" ip="10.9.{i}.1" transport="udp"/>'
                          for i in range(64))
        cfg = write(d, "many.xml", f'<?xml version="1.0"?>\n<ccomm version="1">\n{nodes}\n</ccomm>\n')
        r = in_namespace(f"{CCOMMD} --which-node --config {cfg} || echo \"EXIT $?\"", journal=True)
        assert "EXIT 1" in r.stdout, r.stdout + r.stderr
        line = [l for l in r.stderr.splitlines() if "no node of" in l]
        assert len(line) == 1 and line[0].startswith("<3>ccommd: no node of"), r.stderr
        assert len(line[0]) > 1024 and line[0].endswith("give the node this board's mac= or ip="), line[0][-200:]
