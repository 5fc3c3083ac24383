# SPDX-License-Identifier: Apache-2.0
"""Reload (docs/usage.md, "Reload"): `ccommd --reload PID` (the unit's ExecReload=) and a
plain SIGHUP, while an app on control writes x at 1 kHz and an app on planner reads it.
A broken file changes nothing (values flow throughout, none lost) and fails with
FILE:LINE; a change of local settings keeps the segment (no value missed, no reopen); a
signal change replaces it: applications see CCOMM_E_RETIRED, reopen, and never get a
value of the old configuration in the new segment. The gaps are printed with -s."""
import json
import os
import signal
import subprocess
import sys
import time

from harness import BIN, BUILD, SANITIZED, NodePair, peer_stats, python_env, signal_stats, wait_for

CONFIG = """<?xml version="1.0"?>
<ccomm version="1">
  <network heartbeat_ms="100" peer_timeout_ms="300"/>
  <node name="control" interface="eth0" ip="10.42.0.1" transport="raw"/>
  <node name="planner" interface="eth0" ip="10.42.0.2" transport="raw"/>
  <signal name="x" type="double" producer="control" consumers="planner" stale_after_ms="20"/>
  <signal name="y" type="double" producer="planner" consumers="control" stale_after_ms="20"/>
</ccomm>
"""
BROKEN_LINE = 8  # the bad signal below takes the place of </ccomm>, line 8
BROKEN = CONFIG.replace("</ccomm>", '  <signal name="z" type="bogus" producer="control" consumers="planner"/>\n</ccomm>')
LOCAL_ONLY = CONFIG.replace('peer_timeout_ms="300"', 'peer_timeout_ms="500"')  # not in the hash or layout
NEW_SIGNAL = CONFIG.replace("</ccomm>", '  <signal name="z" type="double" producer="control" consumers="planner"/>\n</ccomm>')

# Both apps follow a segment replacement as an application should: on CCOMM_E_RETIRED
# close, reopen (retrying while ccommd sets the new one up) and find the signal again.
APP = r"""
import ctypes, json, select, sys, time
lib = ctypes.CDLL(sys.argv[1])
role, node, seconds = sys.argv[2], sys.argv[3].encode(), float(sys.argv[4])
class Info(ctypes.Structure):
    _fields_ = [("status", ctypes.c_int32), ("flags", ctypes.c_uint32), ("seq", ctypes.c_uint64),
                ("age_ns", ctypes.c_int64), ("source_time_ns", ctypes.c_uint64), ("lost", ctypes.c_uint64)]
lib.ccomm_find.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
lib.ccomm_close.argtypes = [ctypes.c_void_p]
lib.ccomm_write_double.argtypes = [ctypes.c_void_p, ctypes.c_int32, ctypes.c_double]
lib.ccomm_read_double.argtypes = [ctypes.c_void_p, ctypes.c_int32, ctypes.POINTER(ctypes.c_double), ctypes.POINTER(Info)]
RETIRED = -9
def attach():
    while True:
        h = ctypes.c_void_p()
        if lib.ccomm_open(node, 0, ctypes.byref(h)) == 0:
            s = lib.ccomm_find(h, b"x")
            if s >= 0:
                return h, s
            lib.ccomm_close(h)
        time.sleep(0.001)
h, s = attach()
out = {"retired": [], "reopened": [], "values": [], "never_after_reopen": 0}
v = 0.0
if role == "writer":  # value 1 alone, until the test has seen it arrive (_writer)
    v = 1.0
    lib.ccomm_write_double(h, s, v)
    print("first", flush=True)
    sys.stdin.readline()
# At least `seconds`, and until stdin closes (_result): the test decides when it has seen enough.
end = time.time() + seconds
told = False
last = None
v_out, info = ctypes.c_double(), Info()
while True:
    told = told or bool(select.select([sys.stdin], [], [], 0)[0] and not sys.stdin.readline())
    if told and time.time() >= end:
        break
    if role == "writer":
        v += 1.0
        r = lib.ccomm_write_double(h, s, v)
        time.sleep(0.001)
    else:
        r = lib.ccomm_read_double(h, s, ctypes.byref(v_out), ctypes.byref(info))
        if r >= 0 and info.status == 0 and v_out.value != last:
            last = v_out.value
            out["values"].append([time.time(), last])
        elif r >= 0 and info.status == 2 and out["reopened"]:
            out["never_after_reopen"] += 1
        time.sleep(0.0002)
    if r == RETIRED:
        out["retired"].append(time.time())
        lib.ccomm_close(h)
        h, s = attach()
        out["reopened"].append(time.time())
out["written"] = v
print(json.dumps(out))
"""


def _app(pair, node, role, seconds):
    proc = subprocess.Popen(pair.exec_prefix(node) + [sys.executable, "-c", APP, os.path.join(BUILD, "lib", "libccomm.so"),
                                                      role, node, str(seconds)],
                            env=python_env(pair.env), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    pair.bg.append(proc)
    return proc


def _writer(pair, seconds):
    """The writer on control, once planner has received its first value, x = 1, written
    alone: the planner counts a value lost when it sees the gap after its predecessor, and
    a value control coalesced before planner's first one has none (under load the send
    thread's first round can find several values written: in a TSan run it took x = 11, 1
    to 7 gone from the slots, and planner's first was 8). From value 1 on, every value is
    either received or counted lost there, so lost == coalesced holds exactly."""
    proc = _app(pair, "control", "writer", seconds)
    assert proc.stdout.readline().strip() == "first", proc.communicate(timeout=30)
    assert wait_for(lambda: signal_stats(pair.stats("planner"), "x")["rx"] >= 1, 5), pair.stats("planner")
    proc.stdin.write("go\n")
    proc.stdin.flush()
    return proc


def _result(proc):
    """Ends the app (its stdin closed; it runs at least its `seconds`): what it saw."""
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err
    return json.loads(out.splitlines()[-1])


def _reload(pair, node):
    """`ccommd --reload PID` as ExecReload= runs it: (exit status, its output)."""
    r = run_reload(pair, node)
    return r.returncode, r.stdout + r.stderr


def run_reload(pair, node):
    return subprocess.run(pair.exec_prefix(node) + [os.path.join(BIN, "ccommd"), "-c", pair.config, "--reload",
                                                    str(pair.daemons[node].pid)],
                          env=pair.env, capture_output=True, text=True, timeout=40)


def _segment_inode(pair, node):
    return os.stat("/dev/shm/" + pair.env["CCOMM_SHM_PREFIX"].lstrip("/") + node).st_ino


def _max_gap_ms(values, since=None, until=None):
    ts = [t for t, _ in values if (since is None or t >= since) and (until is None or t <= until)]
    return max((b - a for a, b in zip(ts, ts[1:])), default=0.0) * 1000


def _all_delivered(pair):
    """Once the writer is done: every value it wrote that left control reached planner."""
    def done():
        prod, cons = signal_stats(pair.stats("control"), "x"), signal_stats(pair.stats("planner"), "x")
        return cons["rx"] + cons["lost"] >= prod["tx"]
    wait_for(done, 3)
    return signal_stats(pair.stats("control"), "x"), signal_stats(pair.stats("planner"), "x")


def _start_with_apps(pair, write_s, read_s):
    """Both ccommd, their segments' inodes, control's writer and the planner's reader
    running for about write_s / read_s seconds, one second in."""
    pair.start("control")
    pair.start("planner")
    inodes = {n: _segment_inode(pair, n) for n in ("control", "planner")}
    writer = _writer(pair, write_s)
    reader = _app(pair, "planner", "reader", read_s)
    time.sleep(1.0)
    return inodes, writer, reader


def _assert_every_value_accounted(w, r, prod, cons, gap):
    """Neither app saw its segment retired; every write left or was coalesced; every value
    that left arrived; the reader's longest gap around the reloads stays short."""
    assert not w["retired"] and not r["retired"], (w["retired"], r["retired"])
    assert prod["writes"] == w["written"] and prod["tx"] + prod["coalesced"] == prod["writes"], prod
    # What the planner counts lost is exactly what control coalesced (a state written again
    # before the send thread took it: machine load, also without a reload; test_coalesced.py).
    assert cons["rx"] == prod["tx"] and cons["lost"] == prod["coalesced"], (prod, cons)
    assert gap < (300 if SANITIZED else 100), gap


def test_reload_with_a_broken_file_changes_nothing_and_says_file_line(tmp_path):
    cfg = tmp_path / "signals.xml"
    cfg.write_text(CONFIG)
    with NodePair(config=str(cfg)) as pair:
        inodes, writer, reader = _start_with_apps(pair, 3.0, 3.5)
        cfg.write_text(BROKEN)
        t0 = time.time()
        rc, out = _reload(pair, "planner")
        assert rc == 1, out
        assert "%s:%d:" % (cfg, BROKEN_LINE) in out and "error" in out, out
        pair.daemons["control"].send_signal(signal.SIGHUP)  # a plain kill -HUP: the daemon says it
        assert wait_for(lambda: "reload failed" in pair.log("control"), 3), pair.log("control")
        took = time.time() - t0
        w, r = _result(writer), _result(reader)
        prod, cons = _all_delivered(pair)
        ctl_log = pair.log("control")
        for node in ("control", "planner"):
            assert pair.daemons[node].poll() is None
            assert _segment_inode(pair, node) == inodes[node]
            assert peer_stats(pair.stats(node), "control" if node == "planner" else "planner")["frames_lost"] == 0
    assert "%s:%d:" % (cfg, BROKEN_LINE) in ctl_log, ctl_log
    gap = _max_gap_ms(r["values"], t0 - 0.2, t0 + took + 0.2)
    print("\nbroken file: both reloads refused in %.0f ms; %d values written, %d coalesced, %d sent, %d received, "
          "%d lost; longest gap the reader saw around the reloads %.1f ms" % (
              took * 1000, prod["writes"], prod["coalesced"], prod["tx"], cons["rx"], cons["lost"], gap))
    _assert_every_value_accounted(w, r, prod, cons, gap)


def test_reload_with_a_local_change_keeps_the_segment_and_every_value(tmp_path):
    cfg = tmp_path / "signals.xml"
    cfg.write_text(CONFIG)
    with NodePair(config=str(cfg)) as pair:
        inodes, writer, reader = _start_with_apps(pair, 3.0, 3.5)
        cfg.write_text(LOCAL_ONLY)
        t0 = time.time()
        for node in ("planner", "control"):
            rc, out = _reload(pair, node)
            assert rc == 0, out + pair.log(node)
        took = time.time() - t0
        w, r = _result(writer), _result(reader)
        prod, cons = _all_delivered(pair)
        logs = {n: pair.log(n) for n in ("control", "planner")}
        # The system view was set up again too: both boards in it, both alive.
        view = json.loads(pair.cli("planner", "stats", "--all", "--json").stdout)
        assert view["node"] == "planner", view
        for node in ("control", "planner"):
            assert pair.daemons[node].poll() is None
            assert _segment_inode(pair, node) == inodes[node]
            assert peer_stats(pair.stats(node), "control" if node == "planner" else "planner")["frames_lost"] == 0
    for node, log in logs.items():
        assert "segment kept (same layout)" in log, log
    paused = [float(l.rsplit("paused ", 1)[1].split()[0]) for log in logs.values() for l in log.splitlines()
              if "forwarding paused" in l]
    gap = _max_gap_ms(r["values"], t0 - 0.2, t0 + took + 0.2)
    print("\nlocal change: both reloads in %.0f ms, forwarding paused %s ms; %d values written, %d coalesced, "
          "%d received, %d lost; longest gap the reader saw %.1f ms" % (
              took * 1000, "/".join("%.1f" % p for p in paused), prod["writes"], prod["coalesced"], cons["rx"],
              cons["lost"], gap))
    _assert_every_value_accounted(w, r, prod, cons, gap)


def test_reload_with_a_signal_change_replaces_the_segment_without_old_values(tmp_path):
    cfg = tmp_path / "signals.xml"
    cfg.write_text(CONFIG)
    with NodePair(config=str(cfg)) as pair:
        inodes, writer, reader = _start_with_apps(pair, 4.0, 4.5)
        cfg.write_text(NEW_SIGNAL)
        # The planner first: control still sends frames of the old configuration for 0.5 s.
        t_planner = time.time()
        rc, out = _reload(pair, "planner")
        assert rc == 0, out + pair.log("planner")
        time.sleep(0.5)
        t_control = time.time()
        rc, out = _reload(pair, "control")
        assert rc == 0, out + pair.log("control")
        time.sleep(1.0)  # the apps run on at least this long in the new configuration (slow reloads: TSan)
        w, r = _result(writer), _result(reader)
        wrong_hash = pair.stats("planner")["counters"] if "counters" in pair.stats("planner") else None
        logs = {n: pair.log(n) for n in ("control", "planner")}
        for node in ("control", "planner"):
            assert pair.daemons[node].poll() is None
            assert _segment_inode(pair, node) != inodes[node]
    for log in logs.values():
        assert "segment replaced" in log, log
    assert len(r["retired"]) == 1 and len(w["retired"]) == 1, (r["retired"], w["retired"])
    reopened = r["reopened"][0]
    # In planner's new segment nothing arrives while control runs the old configuration:
    # its frames carry the old config hash and are refused.
    old_in_new = [v for t, v in r["values"] if reopened <= t < t_control]
    assert old_in_new == [], old_in_new
    first_new = next(t for t, _ in r["values"] if t >= t_control)
    last_old = max(t for t, _ in r["values"] if t < r["retired"][0])
    print("\nsignal change: planner's reader saw CCOMM_E_RETIRED %.1f ms after its reload and had reopened "
          "%.1f ms later; first value of the new configuration %.1f ms after control's reload "
          "(control's writer reopened %.1f ms after it); no value for %.0f ms, %.0f ms of it waiting for "
          "control to reload" % ((r["retired"][0] - t_planner) * 1000, (reopened - r["retired"][0]) * 1000,
                                 (first_new - t_control) * 1000, (w["reopened"][0] - t_control) * 1000,
                                 (first_new - last_old) * 1000, (t_control - t_planner) * 1000))
    del wrong_hash
    assert first_new - t_control < (3.0 if SANITIZED else 1.0)


def test_reload_of_what_the_open_socket_was_made_from_is_refused(tmp_path):
    """The transport is set up at start with a capability ccommd has dropped since: a
    reload that changes it fails with FILE:LINE and the node forwards on as before."""
    cfg = tmp_path / "signals.xml"
    cfg.write_text(CONFIG)
    with NodePair(config=str(cfg)) as pair:
        pair.start("control")
        pair.start("planner")
        inode = _segment_inode(pair, "planner")
        cfg.write_text(CONFIG.replace('ip="10.42.0.2"', 'ip="10.42.0.9"'))
        rc, out = _reload(pair, "planner")
        log = pair.log("planner")
        assert rc == 1, out
        assert "did not apply" in out, out
        assert "%s:5: error: node 'planner': ip (10.42.0.2 -> 10.42.0.9) cannot change on a reload" % cfg in log, log
        assert pair.daemons["planner"].poll() is None and _segment_inode(pair, "planner") == inode
        pair.spawn("control", "pub", "x", "3.5", "--rate", "200", "--count", "400")
        assert wait_for(lambda: pair.echo_once("planner", "x") == ("3.5", "fresh"), 3)
