# SPDX-License-Identifier: Apache-2.0
"""ccomm-record's read delay (how long values waited in the segment before the capture read
them, docs/integrations/record.md) leaves out the values already there at the start: those
did not wait for the recorder, and counting them made the figure the time since the last
write before the recording (minutes), whatever the capture did."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("mcap")


def test_values_from_before_the_start_do_not_count_as_read_late(client: object, node: str, tmp_path: Path) -> None:
    client["d"].write(2.5)  # type: ignore[index]
    time.sleep(1.0)  # the value is 1 s old when the recording starts
    out, stats = tmp_path / "r.mcap", tmp_path / "s.json"
    src = str(Path(__file__).resolve().parent.parent / "src")
    env = dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))
    subprocess.run([sys.executable, "-m", "ccomm.record", "-n", node, "-s", "d", "-d", "0.3", "-q",
                    "-o", str(out), "--stats-json", str(stats)], env=env, check=True, timeout=60)
    s = json.loads(stats.read_text())
    assert s["signals"]["d"]["values"] == 1  # the initial value is recorded...
    assert s["read_delay_max_ns"] == 0 and s["reads_delayed_over_1ms"] == 0, s  # ...but did not wait
