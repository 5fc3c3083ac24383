# SPDX-License-Identifier: Apache-2.0
"""This board's clock state from linuxptp (issue 29): ccommd asks ptp4l over its
management socket once a second and shows none / syncing / synced / lost in the API
(ccomm stats reads it through ccomm_get_clock_state) and its log. ptp4l runs in the two
namespaces over the veth pair with software timestamping; control is the grandmaster
(synced: the reference itself), planner a slave-only port, both configured by
`ccommd --clock-config` from the <clock> section of the one signals.xml. Two boards on
one host need two management sockets and must leave the host's clock alone, so the test
changes uds_address and adds free_running (the planner's port then stays UNCALIBRATED:
syncing). Then the planner's ptp4l is killed: lost."""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import pytest

from harness import BIN, BUILD, DEFAULT_CONFIG, NodePair, python_env, wait_for

PTP4L = shutil.which("ptp4l") or ("/usr/sbin/ptp4l" if os.path.exists("/usr/sbin/ptp4l") else None)

CLOCK = '<clock domain="5" grandmaster="control" sync_interval_log="-2"/>\n</ccomm>'
# For two boards on one host only (see above); quick announces so the test is short.
TEST_ONLY = "free_running 1\nlogAnnounceInterval -2\nannounceReceiptTimeout 3\n"


def clock_state(pair, node):
    return pair.stats(node)["clock"]


def clocks_seen_from(pair, viewer):
    """Every node's clock as `viewer`'s `ccomm stats --all --json` shows it (from the
    node summaries): {node: {"state": ..., "error_ns": ... or None}}."""
    view = json.loads(pair.cli(viewer, "stats", "--all", "--json").stdout)
    return {n["name"]: n["clock"] for n in view["nodes"] if n["reported"]}


# A value from the control board, read on the planner once it arrived, and its production age.
PY_AGE = ("import ccomm, json, sys, time\n"
          "c = ccomm.Client(sys.argv[1])\n"
          "deadline = time.monotonic() + 20\n"
          "r = c.read('wheel0_pos')\n"
          "while r.seq == 0 and time.monotonic() < deadline:\n"
          "    time.sleep(0.05)\n"
          "    r = c.read('wheel0_pos')\n"
          "print(json.dumps({'seq': r.seq, 'age': c.production_age('wheel0_pos', r)}))\n")

PY_VIEW = ("import ccomm, json, sys\n"
           "c = ccomm.Client(sys.argv[1])\n"
           "print(json.dumps({n['name']: n['clock'] for n in c.system_view()['nodes'] if n['reported']}))\n")


def run_python(pair, node, program):
    """`program` (printing one JSON line) through the Python API on `node`."""
    env = python_env(pair.env)
    env["CCOMM_LIBRARY"] = os.path.join(BUILD, "lib", "libccomm.so")
    env["PYTHONPATH"] = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python", "src")
    out = subprocess.run(pair.exec_prefix(node) + [sys.executable, "-c", program, node], env=env,
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def clocks_seen_from_python(pair, viewer):
    """The same through the Python API (Client.system_view())."""
    return run_python(pair, viewer, PY_VIEW)


@pytest.mark.skipif(PTP4L is None, reason="needs linuxptp (ptp4l): scripts/setup core")
def test_clock_states_none_synced_syncing_lost():
    work = tempfile.mkdtemp(prefix="ccomm-ptp-")
    try:
        config = os.path.join(work, "signals.xml")
        with open(DEFAULT_CONFIG) as f:
            text = f.read()
        with open(config, "w") as f:
            f.write(text.replace("</ccomm>", CLOCK))
        with NodePair(config=config) as pair:
            sock = {n: os.path.join(work, n + ".sock") for n in ("control", "planner")}
            for node in ("control", "planner"):
                pair.start(node, extra=["--ptp-socket", sock[node]])
            # No ptp4l: none, and `ccomm stats` says that ages are local.
            assert wait_for(lambda: all(clock_state(pair, n)["state"] == "none" for n in sock), 5)
            assert "clock: none" in pair.cli("planner", "stats").stdout
            # ... and every board's clock is in the system view (node summaries), on either board.
            none = {"state": "none", "error_ns": None}
            for viewer in sock:
                assert wait_for(lambda: clocks_seen_from(pair, viewer) == {"control": none, "planner": none}, 10), \
                    clocks_seen_from(pair, viewer)
            ptp = {}
            for node in ("control", "planner"):
                generated = subprocess.run([os.path.join(BIN, "ccommd"), "-c", config, "-n", node, "--clock-config"],
                                           capture_output=True, text=True, check=True).stdout
                assert "domainNumber 5\n" in generated and "network_transport L2\n" in generated, generated
                assert ("priority1 100\n" in generated) if node == "control" else ("slaveOnly 1\n" in generated)
                assert generated.endswith("uds_address /var/run/ptp4l\n[eth0]\n"), generated
                cfg = os.path.join(work, node + ".cfg")
                with open(cfg, "w") as f:
                    f.write(generated.replace("uds_address /var/run/ptp4l\n",
                                              "uds_address %s\n%s" % (sock[node], TEST_ONLY)))
                log = open(os.path.join(work, node + ".log"), "w")
                ptp[node] = subprocess.Popen(pair.exec_prefix(node) + [PTP4L, "-f", cfg, "-m"],  # interface: the file's [eth0]
                                             stdout=log, stderr=subprocess.STDOUT)
                pair.bg.append(ptp[node])
            t0 = time.time()
            # The grandmaster: synced. The slave-only port listening, then uncalibrated: syncing.
            assert wait_for(lambda: clock_state(pair, "control")["state"] == "synced", 30), clock_state(pair, "control")
            synced_after = time.time() - t0
            c = clock_state(pair, "control")
            assert c["port_state"] == 6, c  # MASTER
            assert wait_for(lambda: clock_state(pair, "planner")["port_state"] in (8, 9), 30), clock_state(pair, "planner")
            p = clock_state(pair, "planner")
            assert p["state"] == ("synced" if p["port_state"] == 9 and abs(p["offset_ns"]) <= 1000000 else "syncing"), p
            assert "clock: %s" % p["state"] in pair.cli("planner", "stats").stdout
            # The planner's summaries show the grandmaster synced with error bound 0 (it is the
            # reference), its own clock as its ptp4l has it; the control board sees the same.
            gm = {"state": "synced", "error_ns": 0}
            assert wait_for(lambda: clocks_seen_from(pair, "planner").get("control") == gm, 10), \
                clocks_seen_from(pair, "planner")
            assert wait_for(lambda: clocks_seen_from(pair, "control").get("planner", {}).get("state")
                            == clock_state(pair, "planner")["state"], 10), clocks_seen_from(pair, "control")
            assert clocks_seen_from_python(pair, "planner")["control"] == gm
            table = pair.cli("planner", "stats", "--all").stdout
            assert "synced+-0ns" in table and "CLOCK" in table, table
            # The planner's clock is not synced (free_running): a value that crossed the
            # wire from the synced grandmaster has no production age, never a number.
            pair.cli("control", "pub", "wheel0_pos", "1.5")
            got = run_python(pair, "planner", PY_AGE)
            assert got["seq"] > 0, got
            if clock_state(pair, "planner")["state"] != "synced":
                assert got["age"] == {"known": False, "code": "local_unsynced", "age_ns": None, "error_ns": None,
                                      "production_time_ns": None}, got
            # ptp4l killed: lost within its two missed polls (plus a loaded machine's delay).
            ptp["planner"].send_signal(signal.SIGKILL)
            ptp["planner"].wait()
            killed = time.time()
            assert wait_for(lambda: clock_state(pair, "planner")["state"] == "lost", 15), clock_state(pair, "planner")
            assert wait_for(lambda: clocks_seen_from(pair, "control").get("planner")
                            == {"state": "lost", "error_ns": None}, 10), clocks_seen_from(pair, "control")
            lost_after = time.time() - killed
            assert "clock lost" in pair.log("planner")
            assert clock_state(pair, "control")["state"] == "synced"
            print("\ncontrol synced (grandmaster) %.1f s after ptp4l started; planner %s (port state %d, "
                  "offset %d ns); lost %.1f s after its ptp4l was killed"
                  % (synced_after, p["state"], p["port_state"], p["offset_ns"], lost_after))
    finally:
        shutil.rmtree(work, ignore_errors=True)
