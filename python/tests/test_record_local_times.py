# SPDX-License-Identifier: Apache-2.0
"""Values recorded on the node that writes them, and replayed there (issue 39):

- ccomm-record stamped a polled value `t - age` with t taken at the start of the pass; a
  value written during the pass has age 0, so its receive time came out as t, before its
  own source time on the same clock (29 of 5291 messages, up to 456 us). Every value
  written on the recording node must have receive_time_ns >= source_time_ns.
  With --profile ros2 (no receive time field): the log time (receive) was before the
  publish time (the write, same node) in 115 messages; never now.
- ccomm-replay waited up to 10 ms, once per signal, for ccommd to send a signal no other
  node consumes (its `tx` never moves): the pytest node's signals are all such."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("mcap")

SIGNALS = ["d", "f", "u32", "i64", "flag", "base_x_sp", "base_y_sp", "i32", "vec"]


def _env() -> dict:
    src = str(Path(__file__).resolve().parent.parent / "src")
    return dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))


def _record(client: object, node: str, out: Path, *extra: str) -> None:
    """Records SIGNALS while writing them round-robin every ~20 us for 1.5 s: writes land
    at every point of the recorder's passes, also between its clock read and its reads."""
    recorder = subprocess.Popen([sys.executable, "-m", "ccomm.record", "-n", node, "-s", ",".join(SIGNALS),
                                 "-d", "3", "-q", "-o", str(out), *extra], env=_env())
    time.sleep(1.0)  # the recorder attaches
    sigs = [client[name] for name in SIGNALS]  # type: ignore[index]
    end = time.monotonic() + 1.5
    k = 0
    while time.monotonic() < end:
        k += 1
        s = sigs[k % len(sigs)]
        count = s.info.count
        v = [k % 100] * count if count > 1 else (k % 2 == 0 if s.info.type_name == "bool" else k % 1000)
        s.write(v)
        t = time.perf_counter() + 20e-6
        while time.perf_counter() < t:
            pass
    assert recorder.wait(timeout=60) == 0


def test_local_receive_time_never_before_source_time(client: object, node: str, tmp_path: Path) -> None:
    from mcap.reader import make_reader

    rec = tmp_path / "local.mcap"
    _record(client, node, rec)
    n, before, worst = 0, 0, 0
    with open(rec, "rb") as f:
        for _schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
            m = json.loads(message.data)
            n += 1
            if m["receive_time_ns"] < m["source_time_ns"]:
                before += 1
                worst = max(worst, m["source_time_ns"] - m["receive_time_ns"])
    assert n > 1000, n
    assert before == 0, f"{before} of {n} values received before they were written (up to {worst / 1e3:.0f} us)"


def test_ros2_profile_log_time_never_before_publish_time(client: object, node: str, tmp_path: Path) -> None:
    from mcap.reader import make_reader

    rec = tmp_path / "local-ros2.mcap"
    _record(client, node, rec, "--profile", "ros2")
    n, before = 0, 0
    with open(rec, "rb") as f:
        for _schema, _channel, message in make_reader(f).iter_messages(log_time_order=False):
            n += 1
            before += message.log_time < message.publish_time  # receive before the write
    assert n > 1000, n
    assert before == 0, f"{before} of {n} messages logged (received) before they were published (written)"


def test_replay_of_signals_nobody_forwards_does_not_stall(client: object, node: str, tmp_path: Path) -> None:
    rec = tmp_path / "local.mcap"
    _record(client, node, rec)
    stats = tmp_path / "replay.json"
    r = subprocess.run([sys.executable, "-m", "ccomm.replay", str(rec), "-n", node, "-q", "--stats-json", str(stats)],
                       env=_env(), capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    s = json.loads(stats.read_text())
    print(f"# replay of {s['values']} values of {len(SIGNALS)} local signals: late p50 {s['late_p50_ns'] / 1e3:.0f} us, "
          f"p99 {s['late_p99_ns'] / 1e3:.0f} us, max {s['late_max_ns'] / 1e3:.0f} us; waits {s['waits_over_1ms']}")
    # None of these signals is forwarded: no step may wait for ccommd to send one (it waited
    # 10 ms once per signal, 9 x 10 ms).
    assert s["waits_over_1ms"] == 0 and s["waited_ms"] < 1, s
