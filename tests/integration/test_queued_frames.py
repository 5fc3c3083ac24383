# SPDX-License-Identifier: Apache-2.0
"""Without clock synchronisation, still no stale value read as fresh (issue 29): the
planner's ccommd is stopped for 5 s while the control board writes; the frames queue in
the planner's socket (its ccommd alone stopped, or every process of the board). When it resumes, values written 4-5 s earlier arrive within
milliseconds: each must read as stale with an age of seconds (peer_clock.h), not as fresh
with an age under 1 ms. Raw Ethernet and UDP. Figures are printed with -s."""
import os
import signal
import subprocess
import tempfile
import time

import pytest

from harness import NodePair, peer_stats, wait_for

STALE_MS = 2000  # far below the 4 s the queued values waited, far above a loaded machine's jitter

CONFIG = """<?xml version="1.0" encoding="UTF-8"?>
<ccomm version="1">
  <network ethertype="0x88B5" udp_port="47800" heartbeat_ms="100" peer_timeout_ms="300"/>
  <node name="control" interface="eth0" ip="10.42.0.1" transport="raw"/>
  <node name="planner" interface="eth0" ip="10.42.0.2" transport="raw"/>
  <signal name="setpoint" type="double" producer="control" consumers="planner" stale_after_ms="%d"/>
</ccomm>
""" % STALE_MS


def echo_lines(proc):
    """(value, status, age_us) of every line `ccomm echo` printed."""
    proc.send_signal(signal.SIGTERM)
    try:
        out = proc.communicate(timeout=10)[0]
    except Exception:
        proc.kill()
        out = proc.communicate()[0]
    lines = []
    for line in out.splitlines():
        f = line.split()
        if len(f) >= 5 and f[0] == "setpoint":
            lines.append((f[1], f[2], int(f[4].split("=")[1])))
    return lines


def board_pids(pair, node):
    out = subprocess.run(["ip", "netns", "pids", pair.ns[node]], capture_output=True, text=True, check=True).stdout
    return [int(p) for p in out.split()]


@pytest.mark.parametrize("stopped_part", ["ccommd", "board"])
@pytest.mark.parametrize("transport", ["raw", "udp"])
def test_values_queued_while_ccommd_was_stopped_read_stale(transport, stopped_part):
    with tempfile.NamedTemporaryFile("w", suffix=".xml", delete=False) as f:
        f.write(CONFIG)
    try:
        with NodePair(config=f.name, transport=transport) as pair:
            pair.start("control")
            pair.start("planner")
            # An application on the planner that prints every new value it reads.
            reader = pair.spawn("planner", "echo", "setpoint")
            writer = pair.spawn("control", "pub", "setpoint", "1", "--rate", "200", "--count", "1000000")
            assert wait_for(lambda: pair.echo_once("planner", "setpoint") == ("1", "fresh"), 10)
            writer.kill()
            writer.wait()
            # Stop the planner's ccommd (ip netns exec execs: this pid is ccommd itself),
            # or every process in its namespace (the reading application too).
            planner = pair.daemons["planner"]
            pids = [planner.pid] if stopped_part == "ccommd" else board_pids(pair, "planner")
            assert planner.pid in pids
            for pid in pids:
                os.kill(pid, signal.SIGSTOP)
            stopped = time.monotonic()
            try:
                # Values "2" are written only while it is stopped: every one of them queues.
                tx_before = pair.stats("control")["signals"][0]["tx"]
                pair.cli("control", "pub", "setpoint", "2", "--rate", "200", "--count", "40")
                written = time.monotonic()
                assert pair.stats("control")["signals"][0]["tx"] > tx_before, "nothing was sent"
                # Stopped 5 s, and the newest queued value at least 4 s old on resuming.
                time.sleep(max(stopped + 5.0, written + 4.0) - time.monotonic())
            finally:
                for pid in pids:
                    os.kill(pid, signal.SIGCONT)
            resumed = time.monotonic()
            min_true_age_us = int((resumed - written) * 1e6)
            # The queue drains at once; wait (bounded) until the reader has seen a "2".
            assert wait_for(lambda: pair.echo_once("planner", "setpoint")[0] == "2", 10)
            clock = peer_stats(pair.stats("planner"), "control")["clock"]
            lines = echo_lines(reader)
            queued = [l for l in lines if l[0] == "2"]
            assert queued, "the reader saw none of the queued values: %s" % lines[-5:]
            fresh = [l for l in queued if l[1] == "fresh"]
            print("\n%s, %s stopped: %d queued values read, ages %.3f-%.3f s (written >= %.3f s before the resume); "
                  "frames_delayed %d, queue_delay_max %.0f ms, fresh: %d"
                  % (transport, stopped_part, len(queued), min(l[2] for l in queued) / 1e6, max(l[2] for l in queued) / 1e6,
                     min_true_age_us / 1e6, clock["frames_delayed"], clock["queue_delay_max_ms"], len(fresh)))
            assert not fresh, "values written >= %.1f s earlier read as fresh: %s" % (min_true_age_us / 1e6, fresh[:3])
            # Their ages tell how long they waited (the bound: too young by at most the
            # path's fastest delay plus drift, far below a second here).
            assert all(l[2] >= min_true_age_us - 500000 for l in queued), queued[:3]
            assert clock["frames_delayed"] >= 1 and clock["queue_delay_max_ms"] >= 3500, clock
            # Fresh values flow again afterwards, and read fresh.
            pair.spawn("control", "pub", "setpoint", "3", "--rate", "200", "--count", "1000000")
            assert wait_for(lambda: pair.echo_once("planner", "setpoint") == ("3", "fresh"), 10)
    finally:
        os.unlink(f.name)
