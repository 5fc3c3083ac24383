# SPDX-License-Identifier: Apache-2.0
"""The recorder's writer keeps the file in log-time order when ccommd stores a value after
its receive stamp (a frame that waited in ccommd's socket is stamped with its arrival)."""
from __future__ import annotations

import json
import struct
from pathlib import Path

import pytest

mcap_reader = pytest.importorskip("mcap.reader")

from ccomm._types import SignalInfo, SignalType  # noqa: E402
from ccomm.mcap_io.schema import RECORD, WATERMARK_ID  # noqa: E402
from ccomm.mcap_io.writer import HOLD_MIN_NS, RecordingWriter, WriterOptions  # noqa: E402

MS = 1_000_000


def signal(sid: int, name: str) -> SignalInfo:
    return SignalInfo(id=sid, name=name, type=SignalType.DOUBLE, count=1, value_bytes=8, is_event=False,
                      produced_here=False, stale_after_ms=0, producer="other", consumed_here=True)


def value(sid: int, seq: int, recv_ns: int, prod: tuple = (-1, -1, 3)) -> bytes:
    """A record; `prod`: (production time, its error, age code), default unknown (local_unsynced)."""
    return RECORD.pack(sid, 0, 0, seq, recv_ns, recv_ns, 0, *prod) + struct.pack("<d", float(seq))


def watermark(t_ns: int) -> bytes:
    return RECORD.pack(WATERMARK_ID, 0, 0, 0, t_ns, 0, 0, -1, -1, 0)


def log_times(path: Path) -> list:
    with open(path, "rb") as f:
        return [(ch.topic, m.log_time) for _s, ch, m in
                mcap_reader.make_reader(f).iter_messages(log_time_order=False)]


def write(tmp_path: Path, records: bytes, **options: object) -> tuple:
    w = RecordingWriter(WriterOptions(output=str(tmp_path / "w.mcap"), signals=[signal(0, "a"), signal(1, "b")],
                                      node="monitor", progress="none", **options))  # type: ignore[arg-type]
    w._open()
    buf = bytearray(records)
    assert w.add(buf) == len(buf)
    w._close()
    return w, log_times(tmp_path / "w.mcap")


def test_a_value_stamped_before_the_watermark_within_the_hold_is_written_in_order(tmp_path: Path) -> None:
    t = 1000 * MS
    # b's value arrived at t - 5 ms but ccommd stored it after the capture's turn at t
    w, times = write(tmp_path, value(0, 1, t - 1 * MS) + watermark(t) + value(1, 1, t - 5 * MS)
                     + value(0, 2, t + 1 * MS) + watermark(t + 2 * MS))
    assert [lt for _t, lt in times] == sorted(lt for _t, lt in times)
    assert times[0] == ("b", t - 5 * MS)  # at its own receive time, not moved
    assert w.late == 0


def test_a_value_later_than_the_hold_is_logged_at_the_newest_time_and_counted(tmp_path: Path) -> None:
    t = 1000 * MS
    lag = HOLD_MIN_NS + 30 * MS  # beyond the hold: messages after it were written already
    w, times = write(tmp_path, value(0, 1, t - lag) + value(0, 2, t) + watermark(t + HOLD_MIN_NS + 1 * MS)
                     + value(1, 1, t - lag + 1 * MS) + watermark(t + HOLD_MIN_NS + 2 * MS)
                     + value(1, 2, t + 3 * MS) + watermark(t + 3 * HOLD_MIN_NS))
    order = [lt for _t, lt in times]
    assert order == sorted(order), order
    assert w.late == 1 and w.late_max_ns == lag - 1 * MS
    assert w.hold_ns > HOLD_MIN_NS  # widened after it: the next such value is held long enough
    assert w.summary(1.0)["logged_late"] == 1


def messages(path: Path) -> list:
    with open(path, "rb") as f:
        return [(ch.topic, m.log_time, m.publish_time, m.data) for _s, ch, m in
                mcap_reader.make_reader(f).iter_messages(log_time_order=False)]


@pytest.mark.parametrize("profile", ["ccomm", "ros2"])
def test_publish_time_is_the_production_time_when_known_else_the_receive_time(tmp_path: Path, profile: str) -> None:
    t, offset = 1000 * MS, 1_700_000_000_000_000_000  # CLOCK_REALTIME - CLOCK_MONOTONIC at the start
    produced = offset + t - 40 * MS  # written 40 ms before it arrived, on the common time base
    write(tmp_path, value(0, 1, t, (produced, 7000, 0)) + value(1, 1, t + 1 * MS)
          + watermark(t + HOLD_MIN_NS * 2), clock_offset_ns=offset, profile=profile)
    (a, a_log, a_pub, a_data), (b, b_log, b_pub, b_data) = messages(tmp_path / "w.mcap")
    assert (a, a_log, a_pub) == ("a" if profile == "ccomm" else "/ccomm/a", offset + t, produced)
    assert (b_log, b_pub) == (offset + t + 1 * MS, offset + t + 1 * MS)  # unknown: the receive time
    if profile == "ccomm":
        ma, mb = json.loads(a_data), json.loads(b_data)
        assert (ma["production_time_ns"], ma["production_error_ns"], ma["age_code"]) == (produced, 7000, "synced")
        assert (mb["production_time_ns"], mb["production_error_ns"], mb["age_code"]) == (None, None, "local_unsynced")


def test_an_unwritable_stats_json_is_an_error_that_says_why_and_the_recording_is_complete(
        tmp_path: Path, capfd: pytest.CaptureFixture) -> None:
    import os

    from ccomm.mcap_io.writer import run_writer
    rfd, wfd = os.pipe()
    os.write(wfd, value(0, 1, 1000 * MS) + watermark(1001 * MS))
    os.close(wfd)  # the capture ended: the writer completes the file
    out, stats = tmp_path / "w.mcap", tmp_path / "no-such-dir" / "s.json"
    code = run_writer(rfd, WriterOptions(output=str(out), signals=[signal(0, "a")], node="monitor",
                                         progress="none", stats_json=str(stats)))
    os.close(rfd)
    assert code == 1
    assert f"cannot write {stats}" in capfd.readouterr().err
    assert log_times(out) == [("a", 1000 * MS)]  # the recording itself is complete and readable
