# SPDX-License-Identifier: Apache-2.0
"""ccomm-replay's outputs: an unwritable --stats-json is refused before anything is written
(it ended in a traceback after the replay), and progress off a terminal is whole lines (it
was in-place updates joined by carriage returns)."""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("mcap")


def tool(name: str, *args: str) -> subprocess.CompletedProcess:
    src = str(Path(__file__).resolve().parent.parent / "src")
    env = dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run([sys.executable, "-m", f"ccomm.{name}", *args], env=env, capture_output=True, text=True,
                          timeout=120)


def test_unwritable_stats_json_and_progress_lines(client: object, node: str, tmp_path: Path) -> None:
    rec = tmp_path / "r.mcap"
    src = str(Path(__file__).resolve().parent.parent / "src")
    env = dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))
    recorder = subprocess.Popen([sys.executable, "-m", "ccomm.record", "-n", node, "-s", "f", "-d", "3.5", "-q",
                                 "-o", str(rec)], env=env)
    time.sleep(1.0)  # the recorder attaches (a value written before would be an initial one: no harm)
    end = time.monotonic() + 2.0
    k = 0
    while time.monotonic() < end:  # values spread over 2 s: replay reports progress each second
        k += 1
        client["f"].write(float(k))  # type: ignore[index]
        time.sleep(0.01)
    assert recorder.wait(timeout=60) == 0
    bad = tool("replay", str(rec), "-n", node, "--stats-json", str(tmp_path / "no-such-dir" / "s.json"))
    assert bad.returncode == 1 and "cannot write" in bad.stderr and "Traceback" not in bad.stderr, bad.stderr
    good = tool("replay", str(rec), "-n", node)
    assert good.returncode == 0, good.stderr
    assert "\r" not in good.stderr and "/ " in good.stderr, repr(good.stderr)  # progress lines, no \r
