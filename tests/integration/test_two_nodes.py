# SPDX-License-Identifier: Apache-2.0
"""Two ccommd in two network namespaces: signals flow both ways, over raw Ethernet and UDP."""
import json
import os

import pytest

from harness import BIN, SANITIZED, NodePair, peer_stats, signal_stats, wait_for


@pytest.mark.parametrize("transport", [None, "udp"], ids=["raw", "udp"])
def test_setup_simulation_both_ways(transport):
    with NodePair(transport=transport) as pair:
        pair.start("control")
        pair.start("planner")
        # Exact values, both directions, through the CLI. Published at 200 Hz: these
        # signals go stale 20 ms after the last value (and then read as the safe value).
        # (Read while fresh: a reader that starts late, or a publisher starved for 20 ms,
        # reads "stale" and the safe value, which is right, but not what is checked here.)
        pubs = [pair.spawn("control", "pub", "arm3_torque", "-12.5", "--rate", "200", "--count", "4000"),
                pair.spawn("planner", "pub", "base_theta_sp", "0.785", "--rate", "200", "--count", "4000")]
        assert wait_for(lambda: pair.echo_once("planner", "arm3_torque") == ("-12.5", "fresh"), 10) is not None
        assert wait_for(lambda: pair.echo_once("control", "base_theta_sp") == ("0.785", "fresh"), 10) is not None
        for p in pubs:
            assert p.poll() is None, p.communicate()  # still publishing: nothing failed
            p.terminate()
            p.wait(timeout=10)
        frames_before = peer_stats(pair.stats("control"), "planner")["frames_tx"]
        # The thesis setup-simulation at 1 kHz: 36 doubles one way, 9 back, in parallel.
        lat = os.path.join(BIN, "ccomm-latency")
        a = pair.spawn("control", "--rate", "1000", "--duration", "2", tool="ccomm-latency")
        b = pair.spawn("planner", "--rate", "1000", "--duration", "2", tool="ccomm-latency")
        ra = json.loads(a.communicate(timeout=30)[0])
        rb = json.loads(b.communicate(timeout=30)[0])
        assert lat
        for r, sent_by_peer in ((ra, rb["sent"]), (rb, ra["sent"])):
            if SANITIZED:  # slow build: only that every direction works
                assert r["count"] > 100, r
                continue
            # Judged against what the peer really sent (on a loaded machine a starved sender
            # sends fewer than 2000 cycles in 2 s; CI-like load 13: 426), and by cycle number,
            # not by how many fell in the window after the warm-up (that depends on when the
            # sender was starved): the reader followed the peer to (nearly) its last cycle.
            assert r["count"] > 100 and r["last_k"] >= 0.95 * sent_by_peer, (r, sent_by_peer)
            # Cycles the app did not see whole: a reader late by a period, or one reading while
            # ccommd stores the next frame's 36 values, sees a newer value replace an older one
            # (state semantics, per signal). How many depends on the machine, not on ccomm:
            # 0-10% alone, 18% under two CPU hogs (the reader's own sender thread then
            # measured 85-307 overruns). A timing figure, so it is measured in scripts/bench
            # (docs/performance.md, the thesis set-up); this test holds the loose bound that
            # most cycles arrive whole, and (below) that the wire loses nothing at all.
            assert r["lost"] <= 0.5 * (r["received"] + r["lost"]), json.dumps(
                {"this": r, "control": ra, "planner": rb,
                 "counters": {n: pair.stats(n)["counters"] for n in ("control", "planner")}})
        # On the wire nothing may be lost: a veth pair does not drop frames. A sanitized
        # ccommd (5-15x slower) can fall behind and its socket buffer overflow: counted,
        # bounded.
        for node, peer in (("control", "planner"), ("planner", "control")):
            lost = peer_stats(pair.stats(node), peer)["frames_lost"]
            assert lost <= (0.1 * ra["sent"] if SANITIZED else 0), (node, lost)
        assert ra["send_signals"] == 36 and rb["send_signals"] == 9
        st = pair.stats("planner")
        assert signal_stats(st, "wheel0_pos")["rx"] >= (200 if SANITIZED else 0.75 * ra["sent"])
        assert peer_stats(st, "control")["alive"]
        assert st["counters"]["frames_bad"] == 0
        # One frame per cycle: control sent 36 doubles per cycle in (about) one frame each.
        ctrl = pair.stats("control")
        frames = peer_stats(ctrl, "planner")["frames_tx"] - frames_before
        assert frames <= ra["sent"] + 20, (frames, ra["sent"], ctrl["counters"])  # + a few heartbeats


def test_wrong_config_hash_is_rejected_and_counted(tmp_path):
    """A board running a different signals.xml must not be believed."""
    from harness import DEFAULT_CONFIG
    other = tmp_path / "other.xml"
    other.write_text(open(DEFAULT_CONFIG).read().replace('name="arm5_torque" type="double"',
                                                          'name="arm5_torque" type="float"'))
    with NodePair() as pair:
        pair.start("control")
        pair.config = str(other)
        pair.start("planner")
        pair.cli("control", "pub", "wheel0_pos", "1")
        # Counted as soon as the frame arrives; wait (bounded) rather than guess how long.
        assert wait_for(lambda: pair.stats("planner")["counters"]["frames_wrong_hash"] > 0, 10) is not None
        st = pair.stats("planner")
        assert signal_stats(st, "wheel0_pos")["rx"] == 0


def test_periodic_mode_sends_once_per_period(tmp_path):
    """rate_hz=200 on the control->planner signals: a 1 kHz writer is sent at 200 Hz, one
    frame per period. Re-sent unchanged values repair lost frames but do not refresh the
    receiver: when the writer stops, the signal goes stale there all the same."""
    import time
    from harness import DEFAULT_CONFIG
    cfg = tmp_path / "periodic.xml"
    text = open(DEFAULT_CONFIG).read().replace('producer="control" consumers="planner" stale_after_ms="20"',
                                               'producer="control" consumers="planner" stale_after_ms="50" rate_hz="200"')
    cfg.write_text(text)
    with NodePair(config=str(cfg)) as pair:
        pair.start("control")
        pair.start("planner")
        writer = pair.spawn("control", "pub", "wheel2_cur", "4.5", "--rate", "1000", "--count", "5000")
        time.sleep(0.5)
        t0 = time.time()
        before = peer_stats(pair.stats("control"), "planner")["frames_tx"]
        p0 = pair.stats("planner")
        time.sleep(1.0)
        frames = peer_stats(pair.stats("control"), "planner")["frames_tx"] - before
        p1 = pair.stats("planner")
        elapsed = time.time() - t0  # >= the span between the two reads of control's counter
        # ~200 frames/s (not 1000): never more than one frame per period.
        assert frames <= 200 * elapsed + 5, (frames, elapsed)
        # At most one new value per frame, from one snapshot of the receiver (two nodes'
        # counters read at different moments would not compare).
        rx = signal_stats(p1, "wheel2_cur")["rx"] - signal_stats(p0, "wheel2_cur")["rx"]
        frames_rx = peer_stats(p1, "control")["frames_rx"] - peer_stats(p0, "control")["frames_rx"]
        assert 0 < rx <= frames_rx + 1, (rx, frames_rx)
        # It sends on its period (about 200 a second; 129 under two CPU hogs, where a writer
        # starved by them also leaves periods without a new value: how many is a timing figure).
        assert frames >= 50, frames
        assert wait_for(lambda: pair.echo_once("planner", "wheel2_cur") == ("4.5", "fresh"), 5) is not None
        assert writer.wait(timeout=30) == 0  # 5 s of writes (more on a loaded machine)
        # The writer stopped; ccommd keeps re-sending 4.5 every 5 ms, and it turns stale.
        assert wait_for(lambda: pair.echo_once("planner", "wheel2_cur") == ("4.5", "stale"), 10) is not None
        assert signal_stats(pair.stats("planner"), "wheel0_pos")["rx"] == 0  # never written


def test_threads_named():
    """ccommd names its I/O threads (ps -L, top -H, /proc/PID/task/TID/comm; docs/man/ccommd.8.md)."""
    with NodePair() as pair:
        pair.start("control")
        pid = pair.daemons["control"].pid  # ip netns exec execs ccommd itself
        def names():
            out = []
            for tid in os.listdir("/proc/%d/task" % pid):
                with open("/proc/%d/task/%s/comm" % (pid, tid)) as f:
                    out.append(f.read().strip())
            return sorted(out)
        # Each named once; any other thread is the main one, or a sanitizer's (TSan runs one).
        assert wait_for(lambda: names().count("ccommd-send") == 1 and names().count("ccommd-receive") == 1
                        and "ccommd" in names(), 5), names()
