# SPDX-License-Identifier: Apache-2.0
"""--profile ros2: every channel carries offered_qos_profiles (issue 39: there was none,
though the MCAP ros2 profile requires it and `ros2 bag play` picks its publishers' QoS from
it), the QoS ccomm-ros2's writer offers (docs/integrations/ros2.md): reliable, volatile, a
state keep-last 1 with deadline = stale_after_ms (infinite without one), an event
keep-all; in rosbag2's integer form (rmw enum values), read with an independent YAML parser."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mcap")
yaml = pytest.importorskip("yaml")

INFINITE = {"sec": 9223372036, "nsec": 854775807}  # RMW_DURATION_INFINITE


def test_ros2_channels_offer_the_bridges_qos(node: str, tmp_path: Path) -> None:
    from mcap.reader import make_reader

    out = tmp_path / "ros2.mcap"
    src = str(Path(__file__).resolve().parent.parent / "src")
    env = dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))
    subprocess.run([sys.executable, "-m", "ccomm.record", "-n", node, "--profile", "ros2", "-s", "d,f,ev,vec",
                    "-d", "0.3", "-q", "-o", str(out)], env=env, check=True, timeout=60)
    with open(out, "rb") as f:
        channels = {c.topic: c for c in make_reader(f).get_summary().channels.values()}
    assert set(channels) == {"/ccomm/d", "/ccomm/f", "/ccomm/ev", "/ccomm/vec"}, channels
    want_deadline = {"/ccomm/d": {"sec": 0, "nsec": 300_000_000}}  # signals.xml: stale_after_ms="300"
    for topic, c in channels.items():
        assert "offered_qos_profiles" in c.metadata, (topic, c.metadata)
        profiles = yaml.safe_load(c.metadata["offered_qos_profiles"])
        assert isinstance(profiles, list) and len(profiles) == 1, profiles
        q = profiles[0]
        assert set(q) == {"history", "depth", "reliability", "durability", "deadline", "lifespan", "liveliness",
                          "liveliness_lease_duration", "avoid_ros_namespace_conventions"}, q
        event = topic == "/ccomm/ev"
        assert (q["history"], q["depth"]) == ((2, 0) if event else (1, 1)), (topic, q)  # keep_all / keep_last 1
        assert q["reliability"] == 1 and q["durability"] == 2 and q["liveliness"] == 1, q  # reliable, volatile
        assert q["deadline"] == want_deadline.get(topic, INFINITE), (topic, q)
        assert q["lifespan"] == INFINITE and q["liveliness_lease_duration"] == INFINITE, q
        assert q["avoid_ros_namespace_conventions"] is False, q
