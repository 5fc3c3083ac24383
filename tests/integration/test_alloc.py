# SPDX-License-Identifier: Apache-2.0
"""ccommd makes no heap allocation in steady state (after start-up, before shutdown),
under the 1 kHz setup-simulation, heartbeats, a link flap and the watchdog path."""
import json
import os
import socket

import pytest

from harness import BUILD, NodePair

COUNTER = os.path.join(BUILD, "lib", "ccomm_alloc_counter.so")


@pytest.mark.skipif(not os.path.exists(COUNTER), reason="allocation counter not built (sanitizer build)")
def test_ccommd_steady_state_allocates_nothing(tmp_path):
    # A fake systemd notify socket, so the readiness/watchdog code path runs too.
    notify = str(tmp_path / "notify.sock")
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(notify)
    msgs = []

    def drain():  # like systemd: read every notification, or senders block
        while True:
            try:
                m = sock.recv(4096)
            except OSError:
                return
            if not m:
                return
            msgs.append(m.decode())

    import threading
    threading.Thread(target=drain, daemon=True).start()
    env = {"NOTIFY_SOCKET": notify, "WATCHDOG_USEC": "200000"}
    with NodePair(env=env, preload=COUNTER) as pair:
        pair.start("control")
        pair.start("planner")
        a = pair.spawn("control", "--rate", "1000", "--duration", "2", tool="ccomm-latency")
        b = pair.spawn("planner", "--rate", "1000", "--duration", "2", tool="ccomm-latency")
        assert json.loads(a.communicate(timeout=30)[0])["count"] > 500
        assert json.loads(b.communicate(timeout=30)[0])["count"] > 500
        pair.link("planner", up=False)  # peer loss and recovery paths
        import time
        time.sleep(0.5)
        pair.link("planner", up=True)
        time.sleep(0.5)
        reports = {}
        for node in ("control", "planner"):
            assert pair.stop(node) == 0
            path = "/tmp/%s-%s.alloc" % (pair.ns[node], node)
            with open(path) as f:
                words = f.read().split()
            reports[node] = int(words[1])
            assert int(words[3]) > 10  # start-up allocates: the counter is really counting
            os.unlink(path)
    sock.close()
    assert any("READY=1" in m for m in msgs)
    assert any("WATCHDOG=1" in m for m in msgs)
    print("\nsteady-state allocations: %s" % reports)
    assert reports == {"control": 0, "planner": 0}
