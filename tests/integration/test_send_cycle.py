# SPDX-License-Identifier: Apache-2.0
"""Send on the cycle (<realtime send_cycle_us=...>, docs/usage.md "Send on the cycle"):
`cycle_rounds` counts rounds sent on their instant, `cycle_late` rounds sent after it. A
periodic signal that was never written leaves nothing to send, so its instants are no
rounds: the counters stay 0 (and the send thread does not sleep for them) until a value
is written, then the value leaves on the cycle."""
import os
import tempfile

from harness import NodePair, peer_stats, signal_stats, wait_for

CONFIG = """<ccomm version="1">
  <node name="control" interface="eth0" ip="10.42.0.1" transport="udp"/>
  <node name="planner" interface="eth0" ip="10.42.0.2" transport="udp">
    <realtime send_cycle_us="1000" send_phase_us="250" launch_time="sleep"/>
  </node>
  <signal name="sp" type="double" producer="planner" consumers="control" period_ms="1"/>
</ccomm>
"""


def cycle(pair, node):
    c = pair.stats(node)["counters"]
    return c["cycle_rounds"], c["cycle_late"], c["cycle_launch"]


def test_rounds_count_only_what_is_sent():
    with tempfile.NamedTemporaryFile("w", suffix=".xml", delete=False) as f:
        f.write(CONFIG)
    try:
        with NodePair(config=f.name) as pair:
            pair.start("control")
            pair.start("planner")
            # The peers hear each other's heartbeats: the planner's send thread has run
            # through hundreds of the signal's 1 ms instants by now.
            assert wait_for(lambda: peer_stats(pair.stats("control"), "planner")["alive"], 10), pair.log("planner")
            assert wait_for(lambda: peer_stats(pair.stats("control"), "planner")["heartbeats_rx"] >= 3, 10)
            assert cycle(pair, "planner") == (0, 0, 2), pair.log("planner")  # 2: sleeps (launch_time="sleep")
            pair.cli("planner", "pub", "sp", "1.5")
            assert wait_for(lambda: signal_stats(pair.stats("control"), "sp")["rx"] > 0, 10)
            assert wait_for(lambda: sum(cycle(pair, "planner")[:2]) > 0, 10)
    finally:
        os.unlink(f.name)
