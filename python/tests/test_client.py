# SPDX-License-Identifier: Apache-2.0
"""The Python binding against a real ccommd (see conftest.py)."""
from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np
import pytest

import ccomm
from ccomm import Client, Status, SignalType


def test_open_and_describe(client: Client) -> None:
    assert client.node == "pytest"
    assert client.daemon_alive
    infos = {s.name: s for s in client.signals()}
    assert list(infos)[:3] == ["d", "f", "i32"]
    assert infos["i32"].type == SignalType.INT32 and infos["i32"].count == 3
    assert infos["i32"].dtype == np.int32 and infos["i32"].value_bytes == 12
    assert infos["ev"].is_event and not infos["d"].is_event
    assert infos["d"].stale_after_ms == 300 and infos["d"].produced_here
    assert infos["remote_x"].producer == "remote" and not infos["remote_x"].produced_here
    assert repr(client["i32"]) == "<Signal i32 int32[3] state>"


def test_unknown_node_and_signal(client: Client) -> None:
    with pytest.raises(ccomm.NotFoundError):
        Client("no-such-node")
    with pytest.raises(ccomm.NotFoundError) as e:
        client.signal("nope")
    assert isinstance(e.value, LookupError) and e.value.code == -2


def test_scalar_roundtrip_and_metadata(client: Client) -> None:
    s = client.signal("d")
    before = s.read().seq
    t0 = time.monotonic_ns()
    s.write(2.5)
    r = s.read()
    assert r.value == 2.5 and isinstance(r.value, float)
    assert r.status == Status.FRESH and r.fresh and not r.safe_value
    assert r.seq == before + 1
    assert r.age_ns is not None and 0 <= r.age_ns < 1_000_000_000  # generous: CI machines are busy
    assert abs(r.source_time_ns - t0) < 1_000_000_000
    s.write(-7)
    assert s.read().value == -7.0 and s.read().seq == before + 2


def test_stale_gives_safe_value(client: Client) -> None:
    s = client.signal("d")
    s.write(3.0)
    assert s.read().value == 3.0
    time.sleep(0.7)  # stale_after_ms = 300
    r = s.read()
    assert r.status == Status.STALE and r.safe_value and r.value == -1.5


def test_types(client: Client) -> None:
    client.write("f", 0.25)
    assert client.read("f").value == 0.25
    client.write("u32", 4_000_000_000)
    assert client.read("u32").value == 4_000_000_000
    client.write("i64", -(2**40))
    assert client.read("i64").value == -(2**40)
    client.write("flag", True)
    r = client.read("flag")
    assert r.value is True
    client.write("flag", 0)
    assert client.read("flag").value is False


def test_arrays_numpy(client: Client) -> None:
    s = client.signal("i32")
    s.write([1, -2, 3])
    r = s.read()
    assert isinstance(r.value, np.ndarray) and r.value.dtype == np.int32
    assert r.value.tolist() == [1, -2, 3]
    s.write(np.array([4.0, 5.0, 6.0]))  # integral floats are fine
    out = np.zeros(3, dtype=np.int32)
    r2 = s.read_into(out)
    assert r2.value is out and out.tolist() == [4, 5, 6]
    s.write(9)  # one value for every element
    assert s.read().value.tolist() == [9, 9, 9]  # type: ignore[union-attr]
    v = client.signal("vec")
    v.write(np.linspace(0.0, 1.0, 4))
    assert np.allclose(v.read().value, [0, 1 / 3, 2 / 3, 1])  # type: ignore[arg-type]
    # The returned array is a copy: later reads do not change it.
    a = v.read().value
    v.write([7, 7, 7, 7])
    assert np.allclose(a, [0, 1 / 3, 2 / 3, 1])  # type: ignore[arg-type]


def test_write_checks(client: Client) -> None:
    with pytest.raises(ValueError):
        client.write("i32", [1, 2])  # wrong length
    with pytest.raises(ValueError):
        client.write("i32", [1.5, 2, 3])  # not integral
    with pytest.raises(OverflowError):
        client.write("i32", [2**31, 0, 0])
    with pytest.raises(OverflowError):
        client.write("u32", -1)
    # Floats at the edge: 2.0**63 equals float(2**63 - 1), so a float64 comparison let it
    # through and it wrapped to -2**63; a float beyond float32 became inf.
    for too_big in (2.0**63, np.float64(2.0**63), [2.0**63]):
        with pytest.raises(OverflowError):
            client.write("i64", too_big)
    client.write("i64", -(2.0**63))
    assert client.read("i64").value == -(2**63)
    with pytest.raises(OverflowError):
        client.write("u32", 2.0**32)
    with pytest.raises(OverflowError):
        client.write("f", 1e39)
    client.write("f", float("inf"))  # inf and nan stay writable, as in signals.xml
    assert client.read("f").value == float("inf")
    with pytest.raises(ValueError):
        client.write("flag", 2)
    with pytest.raises(TypeError):
        client.write("d", "1.0")
    with pytest.raises(ValueError):
        client.signal("i32").read_into(np.zeros(3, dtype=np.int64))
    with pytest.raises(ccomm.NotProducerError) as e:
        client.write("remote_x", 1.0)
    assert e.value.code == -4


def test_never_received(client: Client) -> None:
    r = client.read("remote_x")
    assert r.status == Status.NEVER and r.value == 0.0 and r.seq == 0 and r.age_ns is None


def test_history_of_received_states_only(client: Client) -> None:
    # node "pytest" has history="64": the state it receives keeps a history ring (nothing
    # arrives: "remote" never runs), signals it produces and events have none.
    h = client["remote_x"].history()
    assert h.depth == 64 and h.read() is None and list(h.drain()) == [] and h.overrun == 0
    with pytest.raises(ccomm.NotFoundError):
        client["d"].history()
    with pytest.raises(ccomm.NotFoundError):
        client["ev"].history()


def test_events_are_queued(client: Client, node: str) -> None:
    with Client(node) as reader:
        ev = reader.signal("ev")
        while ev.read().status != Status.EMPTY:  # drain what earlier tests left
            pass
        for v in (10, 20, 30):
            client.write("ev", v)
        got = [ev.read() for _ in range(4)]
        assert [g.value for g in got[:3]] == [10, 20, 30]
        assert all(g.status == Status.FRESH for g in got[:3])
        assert got[3].status == Status.EMPTY and got[3].value is None


def test_wait_wakes_on_write(client: Client, node: str) -> None:
    def writer() -> None:
        time.sleep(0.2)
        with Client(node) as w:
            w.write("d", 42.0)

    t = threading.Thread(target=writer)
    t0 = time.monotonic()
    t.start()
    woke = client.wait(timeout=5.0)
    dt = time.monotonic() - t0
    t.join()
    assert woke and 0.1 < dt < 2.0
    assert client.read("d").value == 42.0


def test_wait_sees_a_write_made_before_the_call(client: Client, node: str) -> None:
    with Client(node) as w:
        w.write("d", 7.0)
    assert client.wait(timeout=0) is True  # written after our open, before the call
    assert client.wait(timeout=0) is False  # reported once


def test_cycle_time(client: Client, node: str) -> None:
    now = Client.now()
    assert abs(now - time.monotonic_ns()) < 1_000_000_000
    with Client(node) as w:
        w.set_time(now - 5_000_000)  # the writer's cycle began 5 ms ago
        w.write("d", 1.25)
    r = client.read("d")
    assert r.source_time_ns == now - 5_000_000 and r.age_ns >= 5_000_000
    client.set_time(now + 10_000_000_000)  # 10 s later: stale (stale_after_ms = 300)
    assert client.read("d").status == Status.STALE
    client.set_time(0)
    assert client.read("d").status == Status.FRESH
    with pytest.raises(ccomm.CcommError):
        client.set_time(-1)


def test_wait_times_out(client: Client) -> None:
    t0 = time.monotonic()
    assert client.wait(timeout=0.15) is False
    assert 0.1 < time.monotonic() - t0 < 1.0


def test_closed_client(node: str) -> None:
    c = Client(node)
    s = c.signal("d")
    c.close()
    assert c.closed
    with pytest.raises(ValueError):
        s.read()
    c.close()  # twice is fine


def test_library_lookup(tmp_path: Path) -> None:
    from ccomm import _native

    with pytest.raises(ccomm.LibraryNotFoundError):
        _native.find_library({"CCOMM_LIBRARY": str(tmp_path / "missing.so")}, [])
    # A build tree inside a source tree (build/NAME/, as scripts/build makes it) is found
    # from a path inside the tree.
    (tmp_path / "src" / "include" / "ccomm").mkdir(parents=True)
    (tmp_path / "src" / "include" / "ccomm" / "ccomm.h").write_text("")
    (tmp_path / "build" / "release" / "lib").mkdir(parents=True)
    lib = tmp_path / "build" / "release" / "lib" / "libccomm.so.0"
    lib.write_text("")
    deep = tmp_path / "python" / "src"
    deep.mkdir(parents=True)
    assert _native.find_library({}, [deep]) == str(lib)
    assert _native.find_library({"CCOMM_BUILD_DIR": str(tmp_path / "build" / "release")}, []) == str(lib)


def test_system_view(client: Client) -> None:
    # The node's own summary is in the view from ccommd's start; "remote" never ran.
    v = client.system_view()
    assert v["node"] == "pytest" and v["summary_ms"] == 1000
    nodes = {n["name"]: n for n in v["nodes"]}
    me, remote = nodes["pytest"], nodes["remote"]
    assert me["self"] and me["reported"] and me["alive"] and me["peers_alive"] == []
    # No ptp4l answers this test's ccommd: its clock is "none", with no error bound.
    assert me["clock"] == {"state": "none", "error_ns": None}
    assert not remote["reported"] and not remote["alive"] and remote["signals"] == []
    sigs = {s["name"]: s for s in me["signals"]}
    assert sigs["d"]["role"] == "producer" and sigs["remote_x"]["role"] == "consumer"
    assert sigs["remote_x"]["stale"] and sigs["remote_x"]["age_ms"] is None  # never received
    assert len(sigs) == 11  # every signal of the file is produced or consumed here
    assert v["summaries"]["tx"] >= 1  # sent to "remote" (nobody listens there)


def test_production_age_never_exact_without_synced_clocks(client: Client) -> None:
    # This test's ccommd has no ptp4l (--ptp-socket none): a value from another node has
    # no production age, never a number; one produced here is exact on this node's clock.
    client.write("d", 2.5)
    r = client.read("d")
    before = Client.now() - r.source_time_ns
    a = client.production_age("d", r)
    after = Client.now() - r.source_time_ns
    assert a["known"] and a["code"] == "same_node" and a["error_ns"] == 0
    assert before <= a["age_ns"] <= after
    # ... and its write on the common (realtime) base: the write moved by realtime - monotonic.
    assert abs(a["production_time_ns"] - (r.source_time_ns + time.time_ns() - Client.now())) < 5_000_000
    remote = client.read("remote_x")
    assert client.production_age("remote_x", remote) == {"known": False, "code": "never", "age_ns": None,
                                                          "error_ns": None, "production_time_ns": None}
    # As if a value had arrived: still unknown, because this board's clock is not synced.
    fake = ccomm.Reading(0.0, ccomm.Status.FRESH, 1, 1000, Client.now() - 1000, 0, False)
    assert client.production_age("remote_x", fake) == {"known": False, "code": "local_unsynced", "age_ns": None,
                                                        "error_ns": None, "production_time_ns": None}
