# SPDX-License-Identifier: Apache-2.0
"""ccomm-record when its writer process is killed (docs/man/ccomm-record.1.md, DESCRIPTION):
exit 1, and the message says so and names --recover (it said "failed (exit -9); see its
message above", and there is no message above)."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("mcap")


def children(pid: int) -> list:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(p) for p in path.read_text().split()] if path.exists() else []


def test_a_killed_writer_is_reported_with_the_recover_hint(node: str, tmp_path: Path) -> None:
    src = str(Path(__file__).resolve().parent.parent / "src")
    env = dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))
    rec = subprocess.Popen([sys.executable, "-m", "ccomm.record", "-n", node, "-q", "-o", str(tmp_path / "r.mcap")],
                           env=env, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 30  # the writer is forked once the recorder attached
        while not children(rec.pid):
            assert rec.poll() is None and time.monotonic() < deadline, rec.stderr.read() if rec.stderr else ""
            time.sleep(0.05)
        os.kill(children(rec.pid)[0], signal.SIGKILL)
        err = rec.communicate(timeout=30)[1]
    finally:
        if rec.poll() is None:
            rec.kill()
            rec.wait()
    assert rec.returncode == 1
    assert "killed (SIGKILL)" in err and "--recover" in err, err
