# SPDX-License-Identifier: Apache-2.0
"""A switch at an agreed instant (`ccommd -c CONFIG --reload PID --at T`, ccommd(8)): ccommd
checks CONFIG.staged when asked and says armed; it switches inside itself at T on its
clock, and only then does the staged file replace CONFIG. Removing the staged file before T
cancels (that is how ccomm deploy aborts); an instant in the past or a broken staged file is
refused with the reason, and nothing changes."""
import os
import subprocess
import time

from harness import BIN, SANITIZED, NodePair, wait_for
from test_deploy import CONFIG, NEW


def _request(pair, node, cfg, at_ns):
    at = "%d.%09d" % divmod(at_ns, 1000000000)
    return subprocess.Popen(pair.exec_prefix(node) + [os.path.join(BIN, "ccommd"), "-c", str(cfg), "--reload",
                                                      str(pair.daemons[node].pid), "--at", at],
                            env=pair.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _start(tmp_path, pair):
    cfg = tmp_path / "planner.xml"
    cfg.write_text(CONFIG)
    pair.start("planner", extra=["-c", str(cfg)])
    return cfg


def test_switch_at_the_instant_then_the_file_moves(tmp_path):
    with NodePair() as pair:
        cfg = _start(tmp_path, pair)
        (tmp_path / "planner.xml.staged").write_text(NEW)
        lead = 3.0 if SANITIZED else 1.5
        at = time.time_ns() + int(lead * 1e9)
        req = _request(pair, "planner", cfg, at)
        armed = req.stdout.readline()
        t_armed = time.time_ns()
        assert armed.split() == ["armed", str(at)], (armed, req.stderr.read())
        assert t_armed < at, "armed %.0f ms after the instant" % ((t_armed - at) / 1e6)
        # Armed: nothing has changed yet, the file in place is still the old one.
        assert cfg.read_text() == CONFIG and "reloaded" not in pair.log("planner")
        out, err = req.communicate(timeout=30)
        assert req.returncode == 0, err
        f = out.split()
        assert f[0] == "switched" and int(f[1]) == at, out
        applied = int(f[2])
        log = pair.log("planner")
        line = next((ln for ln in log.splitlines() if "at the agreed instant + " in ln), log)
        assert "at the agreed instant + " in line, log
        late_ms = float(line.split("at the agreed instant + ", 1)[1].split()[0])
        assert cfg.read_text() == NEW and (tmp_path / "planner.xml.previous").read_text() == CONFIG
        assert not (tmp_path / "planner.xml.staged").exists() and not (tmp_path / "planner.xml.staged.at").exists()
        assert pair.daemons["planner"].poll() is None
        z = [s for s in pair.stats("planner")["signals"] if s["name"] == "z"]
    print("\nswitch at: armed %.0f ms before the instant; ccommd began the switch %.1f ms after it, the "
          "requester had its answer %.1f ms after it" % ((at - t_armed) / 1e6, late_ms, (applied - at) / 1e6))
    assert z, "the new signal z is not in the running configuration"
    assert 0 <= late_ms < (50 if SANITIZED else 20), line


def test_switch_at_is_cancelled_when_the_staged_file_goes(tmp_path):
    with NodePair() as pair:
        cfg = _start(tmp_path, pair)
        staged = tmp_path / "planner.xml.staged"
        staged.write_text(NEW)
        at = time.time_ns() + int((4.0 if SANITIZED else 2.0) * 1e9)
        req = _request(pair, "planner", cfg, at)
        assert req.stdout.readline().startswith("armed "), req.stderr.read()
        staged.unlink()  # ccomm deploy's abort
        out, err = req.communicate(timeout=30)
        assert req.returncode == 1, (out, err)
        assert "did not switch" in err, err
        assert wait_for(lambda: "switch to %s is cancelled" % staged in pair.log("planner"), 3), pair.log("planner")
        assert cfg.read_text() == CONFIG and not (tmp_path / "planner.xml.previous").exists()
        assert "reloaded" not in pair.log("planner") and pair.daemons["planner"].poll() is None


def test_switch_at_refuses_a_past_instant_and_a_broken_staged_file(tmp_path):
    with NodePair() as pair:
        cfg = _start(tmp_path, pair)
        staged = tmp_path / "planner.xml.staged"
        staged.write_text(NEW)
        req = _request(pair, "planner", cfg, time.time_ns() - int(1e9))
        out, err = req.communicate(timeout=30)
        assert req.returncode == 1 and "past" in err and not out, (out, err)
        staged.write_text(NEW.replace('type="double" producer="planner"', 'type="doubel" producer="planner"'))
        req = _request(pair, "planner", cfg, time.time_ns() + int(5e9))
        out, err = req.communicate(timeout=30)
        assert req.returncode == 1 and "%s:7:" % staged in err and "unknown type" in err, (out, err)
        assert cfg.read_text() == CONFIG and "reloaded" not in pair.log("planner")
        assert pair.daemons["planner"].poll() is None
        # ccommd itself refuses an instant that is not in the near future.
        r = subprocess.run([os.path.join(BIN, "ccommd"), "-c", str(cfg), "--reload", "1", "--at", "soon"],
                           capture_output=True, text=True, timeout=10)
        assert r.returncode == 2 and "--at takes seconds since the epoch" in r.stderr, r.stderr
