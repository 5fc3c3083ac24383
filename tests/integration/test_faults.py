# SPDX-License-Identifier: Apache-2.0
"""Faults from the core issue: a writer killed mid-stream, ccommd stopped under running
apps, the link cut; and an operator's second ccommd for a running node. Figures (detection times) are printed with -s."""
import json
import os
import signal
import time

from harness import BIN, SANITIZED, NodePair, peer_stats, signal_stats, run, wait_for

STALE_MS = 20  # dist/signals.xml: stale_after_ms of every signal


def test_kill9_writer_mid_stream():
    with NodePair() as pair:
        pair.start("control")
        pair.start("planner")
        writer = pair.spawn("control", "pub", "wheel0_pos", "1.5", "--rate", "5000", "--count", "1000000")
        reader = pair.spawn("planner", "echo", "wheel0_pos", "--interval", "5")
        time.sleep(0.5)
        os.kill(writer.pid, signal.SIGKILL)  # ip netns exec execs, so this is ccomm itself
        writer.wait()
        # Daemons and other clients carry on: a second writer gets through at once.
        pair.spawn("control", "pub", "wheel0_pos", "2.5", "--rate", "200", "--count", "400")
        assert wait_for(lambda: pair.echo_once("planner", "wheel0_pos") == ("2.5", "fresh"), 3), \
            pair.cli("planner", "stats").stdout
        for node in ("control", "planner"):
            assert pair.daemons[node].poll() is None
            assert pair.stats(node)["daemon_alive"]
        assert reader.poll() is None  # the other client kept running
        reader.kill()
        out = reader.communicate()[0].split("\n")
        assert any(" 1.5 fresh" in l for l in out) and any(" 2.5 fresh" in l for l in out)


def test_stop_ccommd_apps_read_stale_then_recover():
    with NodePair() as pair:
        pair.start("control")
        pair.start("planner")
        pair.spawn("control", "pub", "wheel1_vel", "7", "--rate", "500", "--count", "5000")
        # A long-running app on planner, attached before, during and after the restart.
        app = pair.spawn("planner", "echo", "wheel1_vel", "--interval", "2")
        assert wait_for(lambda: pair.echo_once("planner", "wheel1_vel") == ("7", "fresh"), 3)
        t0 = time.time()
        assert pair.stop("planner") == 0  # SIGTERM: clean exit
        stale_after = wait_for(lambda: pair.echo_once("planner", "wheel1_vel")[1] == "stale", 2, 0.002)
        assert stale_after is not None
        # Last value is kept (no safe value configured for measurements).
        assert pair.echo_once("planner", "wheel1_vel") == ("7", "stale")
        time.sleep(0.3)
        pair.start("planner")  # re-adopts the segment: the running app is not disturbed
        assert "re-adopted" in pair.log("planner")
        back = wait_for(lambda: pair.echo_once("planner", "wheel1_vel")[1] == "fresh", 3)
        assert back is not None
        time.sleep(0.1)
        app.kill()
        seen = [l.split()[2] for l in app.communicate()[0].splitlines() if l.startswith("wheel1_vel")]
        # The same process saw fresh, then stale, then fresh again.
        first_stale = seen.index("stale")
        assert "fresh" in seen[:first_stale] and "fresh" in seen[first_stale:]
        print("\nstale %.1f ms after ccommd stop (stale_after_ms=%d), fresh %.0f ms after restart"
              % (stale_after * 1000, STALE_MS, back * 1000))
        assert time.time() - t0 < 10


def test_link_down_goes_stale_and_recovers():
    with NodePair() as pair:
        pair.start("control")
        pair.start("planner")
        pair.spawn("control", "pub", "arm0_pos", "0.25", "--rate", "1000", "--count", "10000")
        assert wait_for(lambda: pair.echo_once("planner", "arm0_pos")[1] == "fresh", 3)
        before = signal_stats(pair.stats("planner"), "arm0_pos")["stale_transitions"]
        t_down = time.time()
        pair.link("planner", up=False)
        stale = wait_for(lambda: pair.echo_once("planner", "arm0_pos")[1] == "stale", 2, 0.002)
        assert stale is not None
        # Measured from the command, so this includes the `ip` command and a CLI start-up per
        # poll (100-350 ms on a loaded machine): only that it comes soon, not a latency (the
        # QEMU case 30-link-cut times the first stale reading in-process: 22-25 ms).
        assert stale < STALE_MS / 1000 + 1.0, stale
        peer_down = wait_for(lambda: not peer_stats(pair.stats("planner"), "control")["alive"], 2)
        assert peer_down is not None
        st = pair.stats("planner")
        assert peer_stats(st, "control")["down_transitions"] >= 1
        assert signal_stats(st, "arm0_pos")["stale"]
        wait_for(lambda: signal_stats(pair.stats("planner"), "arm0_pos")["stale_transitions"] > before, 1)
        assert signal_stats(pair.stats("planner"), "arm0_pos")["stale_transitions"] > before
        time.sleep(0.3)
        pair.link("planner", up=True)
        fresh = wait_for(lambda: pair.echo_once("planner", "arm0_pos")[1] == "fresh", 5)
        assert fresh is not None
        assert wait_for(lambda: peer_stats(pair.stats("planner"), "control")["alive"], 2) is not None
        lost = peer_stats(pair.stats("planner"), "control")["frames_lost"]
        print("\nlink down: stale after %.1f ms, peer lost after %.0f ms; link up: fresh after %.0f ms; "
              "frames lost while down: %d" % (stale * 1000, peer_down * 1000, fresh * 1000, lost))
        assert lost > 0  # frames sent during the outage are counted as lost
        assert time.time() - t_down < 15


def test_second_ccommd_for_a_node_is_refused_and_a_clean_stop_removes_the_view():
    """A second ccommd for a running node (a hand-started one next to the unit) is refused
    before it touches the segment or the system view; the running one carries on. A clean
    stop removes the node's system view (the segment stays for the apps)."""
    with NodePair() as pair:
        pair.start("control")
        pair.start("planner")
        pair.spawn("control", "pub", "wheel0_pos", "4.5", "--rate", "200", "--count", "100000")
        assert wait_for(lambda: pair.echo_once("planner", "wheel0_pos") == ("4.5", "fresh"), 3)
        first = pair.daemons["planner"].pid
        t0 = time.time()
        second = run(pair.exec_prefix("planner") + [os.path.join(BIN, "ccommd"), "--node", "planner", "--no-rt",
                                                    "-c", pair.config], check=False, env=pair.env, timeout=10)
        took = time.time() - t0
        assert second.returncode != 0, second.stdout + second.stderr
        assert "already running (pid %d;" % first in second.stdout + second.stderr, second.stdout + second.stderr
        assert pair.daemons["planner"].poll() is None
        assert wait_for(lambda: pair.echo_once("planner", "wheel0_pos") == ("4.5", "fresh"), 1)
        assert pair.stats("planner")["daemon_alive"]
        assert json.loads(pair.cli("planner", "stats", "--all", "--json").stdout)["node"] == "planner"
        shm = "/dev/shm/" + pair.env["CCOMM_SHM_PREFIX"].lstrip("/") + "planner"
        assert os.path.exists(shm) and os.path.exists(shm + ".view")
        assert pair.stop("planner") == 0
        assert os.path.exists(shm) and not os.path.exists(shm + ".view")
        gone = pair.cli("planner", "stats", "--all", check=False)
        assert gone.returncode != 0 and "no system view" in gone.stderr, gone.stdout + gone.stderr
        print("\nsecond ccommd refused in %.0f ms: %s" % (took * 1000, (second.stdout + second.stderr).strip()))
