# SPDX-License-Identifier: Apache-2.0
"""Tests of the bench programs and of benchlib (run from scripts/):

    CCOMM_BENCH_BIN=<dir with shm_floor, net_floor> python3 -m unittest -v benchlib.test_benchlib

Program tests are skipped when the programs are not found; the ones needing
network namespaces are skipped unless run as root.
"""

import json
import os
import socket
import subprocess
import sys
import tempfile
import time
import unittest

from . import ccomm as ccomm_mod, formatting, procs, results, targets

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


def _bin_dir():
    for d in (os.environ.get("CCOMM_BENCH_BIN"), os.path.join(REPO, "build", "bench-floors", "bin")):
        if d and os.path.exists(os.path.join(d, "shm_floor")):
            return d
    return None


BIN = _bin_dir()


def prog(name):
    p = os.path.join(BIN, name) if BIN else None
    if not p or not os.path.exists(p):
        raise unittest.SkipTest("%s not built" % name)
    return p


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_beside(partner_argv, main_argv, timeout=60, partner_exit=30, env=None):
    """Runs main_argv while partner_argv (an echo or a sink) runs beside it, then gives the
    partner `partner_exit` s to exit by itself (on the FIN) before killing it. Returns
    both as CompletedProcess (text, stdout and stderr captured)."""
    partner = subprocess.Popen(partner_argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        main = subprocess.run(main_argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              timeout=timeout)
    except BaseException:
        partner.kill()
        partner.communicate()
        raise
    try:
        out, err = partner.communicate(timeout=partner_exit)
    except subprocess.TimeoutExpired:
        partner.kill()
        out, err = partner.communicate()
    return main, subprocess.CompletedProcess(partner_argv, partner.returncode, out, err)


class StatsTest(unittest.TestCase):
    def test_nearest_rank(self):
        v = list(range(1, 101))  # 1..100
        self.assertEqual(results.percentile(v, 0.50), 50)
        self.assertEqual(results.percentile(v, 0.90), 90)
        self.assertEqual(results.percentile(v, 0.99), 99)
        self.assertEqual(results.percentile(v, 0.999), 100)
        self.assertEqual(results.percentile([7], 0.5), 7)
        self.assertEqual(results.percentile([], 0.5), 0)

    def test_row_from_samples(self):
        r = results.row_from_samples("x", "shm", 8, 0, [30, 10, 20], lost=2, metric="rtt")
        self.assertEqual((r["min_ns"], r["p50_ns"], r["max_ns"], r["count"], r["lost"]), (10, 20, 30, 3, 2))
        self.assertAlmostEqual(r["mean_ns"], 20.0)

    def test_validate_rejects(self):
        good = results.row_from_samples("x", "udp", 8, 1000, [1, 2, 3], 0)
        for f in results.SCHEMA_FIELDS:
            bad = dict(good)
            del bad[f]
            with self.assertRaises(results.SchemaError):
                results.validate(bad)
        bad = dict(good, p50_ns=5)  # above p90
        with self.assertRaises(results.SchemaError):
            results.validate(bad)
        with self.assertRaises(results.SchemaError):
            results.validate(dict(good, count="3"))
        with self.assertRaises(results.SchemaError):
            results.validate(dict(good, metric="latency"))

    def test_write_load_table(self):
        rows = [results.row_from_samples("a_row", "raw", 72, 1000, [1000, 2000, 3000], 1, metric="rtt"),
                results.row_from_samples("b_row", "shm", 8, 0, [100], 0, metric="rtt_half")]
        with tempfile.TemporaryDirectory() as d:
            results.write_results(d, rows, {"k": 1}, [{"name": "c", "status": "skipped", "reason": "r"}])
            doc = results.load_results(d)
            self.assertEqual([r["name"] for r in doc["results"]], ["a_row", "b_row"])
            self.assertEqual(doc["skipped"][0]["name"], "c")
        t = results.format_table(rows)
        self.assertIn("a_row", t)
        self.assertIn("b2b", t)
        self.assertIn("2.00", t)  # p50 2000 ns in us


    def test_merge_rows(self):
        with tempfile.TemporaryDirectory() as src, tempfile.TemporaryDirectory() as out:
            with open(os.path.join(src, "x.tsv"), "w") as f:
                f.write("0\t100\n1\t-1\n")
            row = results.row_from_samples("ccomm_x", "raw", 8, 1000, [100], 1, group="net", raw="x.tsv")
            with open(os.path.join(src, "rows.jsonl"), "w") as f:
                f.write("noise\n" + json.dumps(row) + "\n")
            rows = results.adopt_rows(results.load_rows(os.path.join(src, "rows.jsonl")), out)
            self.assertEqual(rows[0]["raw"], os.path.join("raw", "ccomm_x.tsv"))
            self.assertEqual(results.load_raw(os.path.join(out, rows[0]["raw"])), [(0, 100), (1, -1)])


class DaemonCpuSamplerTest(unittest.TestCase):
    """The daemons' share of a measured window, read off samples between them."""

    def sampler(self, samples):
        s = ccomm_mod.DaemonCpuSampler(None, ["a", "b"])
        s.samples = samples
        return s

    def test_interpolates_between_samples(self):
        s = self.sampler([(0, {"a": 0, "b": 0}), (100, {"a": 1000, "b": 10}), (200, {"a": 1000, "b": 30})])
        self.assertEqual(s.between(50, 150), 500 + 15)   # a: 500 -> 1000, b: 5 -> 20
        self.assertEqual(s.between(100, 200), 0 + 20)

    def test_clamps_outside_the_samples(self):
        s = self.sampler([(100, {"a": 10, "b": 0}), (200, {"a": 20, "b": 0})])
        self.assertEqual(s.between(0, 1000), 10)
        self.assertIsNone(self.sampler([]).between(0, 1))


class PairedRatioTest(unittest.TestCase):
    """The board-to-board target is judged on the median of the alternations' ratios."""

    def row(self, name, p50s):
        r = results.row_from_samples(name, "raw", 8, 1000, [sorted(p50s)[len(p50s) // 2]] * 3, 0)
        r["rep_p50_ns"] = p50s
        return r

    def test_one_bad_alternation_does_not_decide(self):
        # Three alternations at 1.1x, one at 3x (a burst of load): pooled p50 would say
        # 1.4x here; the median of the pairs says 1.1x.
        c = self.row("ccomm_raw_oneway_block_1khz_p8", [55000, 55000, 55000, 150000])
        f = self.row("net_raw_oneway_1khz_p8", [50000, 50000, 50000, 50000])
        c["p50_ns"], f["p50_ns"] = 70000, 50000
        ck = [k for k in targets.checks(formatting.Rows([c, f]), {})
              if k["text"].startswith("board->board raw one-way, 8 B")][0]
        self.assertEqual(ck["status"], "met")
        self.assertIn("median **1.10x**", ck["detail"])

    def test_all_alternations_over_is_missed(self):
        c = self.row("ccomm_raw_oneway_block_1khz_p8", [70000, 72000, 68000, 71000])
        f = self.row("net_raw_oneway_1khz_p8", [50000, 50000, 50000, 50000])
        ck = [k for k in targets.checks(formatting.Rows([c, f]), {})
              if k["text"].startswith("board->board raw one-way, 8 B")][0]
        self.assertEqual(ck["status"], "MISSED")

    def test_closing_floor_half_brackets_each_ccomm_half(self):
        # Floor drifting 40 -> 60 us over the run, ccomm always 1.1x the floor of its moment:
        # against the floor half before it alone it reads 1.2-1.38x, against the mean of the
        # halves around it 1.1x.
        c = self.row("ccomm_raw_oneway_block_1khz_p8", [49500, 60500, 71500, 82500])
        f = self.row("net_raw_oneway_1khz_p8", [40000, 50000, 60000, 70000, 80000])
        self.assertEqual([round(x, 3) for x in formatting.paired_ratios(c, f)], [1.1, 1.1, 1.1, 1.1])
        self.assertEqual([round(x, 3) for x in formatting.paired_ratios(c, dict(f, rep_p50_ns=f["rep_p50_ns"][:4]))],
                         [1.238, 1.21, 1.192, 1.179])

    def test_unpaired_rows_fall_back_to_pooled(self):
        self.assertEqual(formatting.paired_ratios({"rep_p50_ns": [1, 2]}, {"rep_p50_ns": [1]}), [])
        self.assertEqual(formatting.median([3.0, 1.0, 2.0, 10.0]), 2.5)


class ProgramTest(unittest.TestCase):
    """Run the programs briefly; check their statistics against their own raw dump."""

    def check_against_dump(self, row, dump, expect_count=None):
        raw = results.load_raw(dump)
        got = [ns for _, ns in raw if ns >= 0]
        lost = sum(1 for _, ns in raw if ns < 0)
        ref = results.row_from_samples(row["name"], row["transport"], row["payload_bytes"], row["rate_hz"],
                                       got, lost)
        for f in ("min_ns", "p50_ns", "p90_ns", "p99_ns", "p999_ns", "max_ns", "count", "lost"):
            self.assertEqual(row[f], ref[f], f)
        self.assertAlmostEqual(row["mean_ns"], ref["mean_ns"], delta=1.0)
        if expect_count is not None:
            self.assertEqual(row["count"] + row["lost"], expect_count)

    def test_shm_modes(self):
        exe = prog("shm_floor")
        with tempfile.TemporaryDirectory() as d:
            for mode, count in (("spin", 3000), ("futex", 300), ("eventfd", 300)):
                dump = os.path.join(d, mode + ".tsv")
                out = subprocess.run([exe, "--mode", mode, "--count", str(count), "--warmup", "10", "--half",
                                      "--dump", dump], stdout=subprocess.PIPE, text=True, timeout=60, check=True)
                row = results.parse_program_output(out.stdout)
                self.assertEqual(row["metric"], "rtt_half")
                self.assertEqual(row["lost"], 0)
                self.assertGreater(row["min_ns"], 0)
                self.check_against_dump(row, dump, count)

    def test_bad_usage(self):
        exe = prog("net_floor")
        for args in (["--transport", "udp"], ["--transport", "tcp", "--role", "ping"],
                     ["--transport", "raw", "--role", "ping"], ["--transport", "udp", "--role", "ping",
                                                                "--payload", "99999"]):
            self.assertEqual(subprocess.run([exe] + args, stderr=subprocess.DEVNULL).returncode, 2, args)
        self.assertEqual(subprocess.run([prog("shm_floor"), "--mode", "x"], stderr=subprocess.DEVNULL).returncode, 2)

    def _udp_pair(self, port, ping_args, echo_args=()):
        exe = prog("net_floor")
        # The echo exits on the ping's FIN (or its --echo-limit).
        ping, _ = run_beside([exe, "--transport", "udp", "--role", "echo", "--bind", "127.0.0.1:%d" % port]
                             + list(echo_args),
                             [exe, "--transport", "udp", "--role", "ping", "--peer", "127.0.0.1:%d" % port] + ping_args,
                             partner_exit=3)
        return ping.returncode, ping.stdout

    def test_udp_loopback_rtt(self):
        with tempfile.TemporaryDirectory() as d:
            dump = os.path.join(d, "u.tsv")
            rc, out = self._udp_pair(free_udp_port(), ["--rate", "0", "--count", "500", "--warmup", "20",
                                                       "--payload", "288", "--dump", dump])
            self.assertEqual(rc, 0)
            row = results.parse_program_output(out)
            self.assertEqual((row["transport"], row["metric"], row["payload_bytes"]), ("udp", "rtt", 288))
            self.assertEqual(row["lost"], 0)
            self.check_against_dump(row, dump, 500)

    def test_udp_loss_is_counted(self):
        # The echo answers 10 warm-up + 100 measured pings, then exits: exactly 200 of
        # the 300 measured must be lost (late answers cannot exist: there are none). The
        # reply deadline is generous so that a loaded machine cannot turn an answered
        # ping into a lost one.
        with tempfile.TemporaryDirectory() as d:
            dump = os.path.join(d, "l.tsv")
            rc, out = self._udp_pair(free_udp_port(), ["--rate", "2000", "--count", "300", "--warmup", "10",
                                                       "--timeout-ms", "1000", "--dump", dump],
                                     echo_args=["--echo-limit", "110"])
            self.assertEqual(rc, 0)
            row = results.parse_program_output(out)
            self.assertEqual((row["count"], row["lost"], row["sent"]), (100, 200, 310))
            self.check_against_dump(row, dump, 300)
            lost_seqs = [seq for seq, ns in results.load_raw(dump) if ns < 0]
            self.assertEqual(lost_seqs, list(range(110, 310)))

    def test_no_peer_fails(self):
        exe = prog("net_floor")
        cp = subprocess.run([exe, "--transport", "udp", "--role", "ping", "--peer", "127.0.0.1:%d" % free_udp_port(),
                             "--start-wait-ms", "200", "--count", "10"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, timeout=30)
        self.assertEqual(cp.returncode, 1)
        self.assertEqual(cp.stdout, "")

    def test_udp_oneway(self):
        exe = prog("net_floor")
        port = free_udp_port()
        with tempfile.TemporaryDirectory() as d:
            dump = os.path.join(d, "o.tsv")
            common = ["--transport", "udp", "--rate", "2000", "--count", "400", "--warmup", "10", "--payload", "72"]
            src, sink = run_beside([exe, "--role", "sink", "--bind", "127.0.0.1:%d" % port, "--dump", dump] + common,
                                   [exe, "--role", "source", "--peer", "127.0.0.1:%d" % port] + common)
            self.assertEqual(src.returncode, 0, src.stderr)
            self.assertEqual(sink.returncode, 0, sink.stderr)
            row = results.parse_program_output(sink.stdout)
            self.assertEqual(row["metric"], "one_way")
            self.assertEqual(row["sent"], 410)
            self.assertGreater(row["min_ns"], 0)
            self.check_against_dump(row, dump, 400)

    @unittest.skipUnless(os.geteuid() == 0, "network namespaces need root")
    def test_raw_in_netns(self):
        exe = prog("net_floor")
        pair = procs.NetnsPair("ccbt%d" % (os.getpid() % 10000))
        with pair:
            cp, _ = run_beside(pair.wrap("b", [exe, "--transport", "raw", "--role", "echo", "--if", "eth0"]),
                               pair.wrap("a", [exe, "--transport", "raw", "--role", "ping", "--if", "eth0",
                                               "--rate", "0", "--count", "300", "--payload", "8"]),
                               partner_exit=3)
        self.assertEqual(cp.returncode, 0, cp.stderr)
        row = results.parse_program_output(cp.stdout)
        self.assertEqual((row["transport"], row["count"], row["lost"], row["wire_bytes"]), ("raw", 300, 0, 60))
        # The namespaces are gone again.
        names = subprocess.run(["ip", "netns", "list"], stdout=subprocess.PIPE, text=True).stdout
        self.assertNotIn(pair.ns_a, names)


class DriverTest(unittest.TestCase):
    def test_smoke_subset(self):
        if not BIN:
            raise unittest.SkipTest("bench programs not built")
        with tempfile.TemporaryDirectory() as d:
            cp = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "bench-floors"), "--smoke",
                                 "--only", "^shm_spin|^net_udp_rtt_b2b", "--build-dir", os.path.dirname(BIN),
                                 "--no-plots", "--netns-prefix", "ccbd%d" % (os.getpid() % 10000), "--out", d],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=120)
            self.assertEqual(cp.returncode, 0, cp.stderr)
            doc = results.load_results(d)
            names = [r["name"] for r in doc["results"]] + [s["name"] for s in doc["skipped"]]
            self.assertIn("shm_spin_b2b_p8", names)
            self.assertIn("net_udp_rtt_b2b_p8", names)
            self.assertIn("shm_spin_b2b_p8", cp.stdout)
            with open(os.path.join(d, "results.json")) as f:
                self.assertIn("meta", json.load(f))
            for r in doc["results"]:
                self.assertTrue(os.path.exists(os.path.join(d, r["raw"])))


class DdsPeerTest(unittest.TestCase):
    """dds_pingpong (Cyclone DDS) on loopback: its statistics agree with its raw dump,
    a round trip is two values, and bad usage is refused."""

    def _run_pair(self, roles, args, tag):
        from . import peers
        exe = prog("dds_pingpong")
        env = dict(os.environ, CYCLONEDDS_URI=peers.dds_config("127.0.0.1", "lo", tag))
        return run_beside([exe, "--role", roles[0], "--idle-ms", "20000"] + args, [exe, "--role", roles[1]] + args,
                          timeout=90, env=env)

    def test_ping_echo_rtt(self):
        with tempfile.TemporaryDirectory() as d:
            dump = os.path.join(d, "d.tsv")
            main, echo = self._run_pair(("echo", "ping"), ["--rate", "0", "--count", "300", "--warmup", "20",
                                                               "--dump", dump, "--reliable"],
                                           "t%d" % os.getpid())
            self.assertEqual(main.returncode, 0, main.stderr)
            row = results.parse_program_output(main.stdout)
            self.assertEqual(row["transport"], "dds_reliable")
            self.assertEqual(row["count"] + row["lost"], 300)
            self.assertEqual(row["values"], 2 * (row["count"] + 20))
            self.assertGreater(row["cpu_ns"], 0)
            self.assertIn('"cpu_ns"', echo.stderr)  # the echo's CPU time, for CPU per value
            ProgramTest.check_against_dump(self, row, dump)

    def test_source_sink_one_way(self):
        with tempfile.TemporaryDirectory() as d:
            dump = os.path.join(d, "s.tsv")
            args = ["--rate", "2000", "--count", "400", "--warmup", "20", "--payload", "288"]
            src, sink = self._run_pair(("sink", "source"), args + ["--dump", dump], "s%d" % os.getpid())
            self.assertEqual(src.returncode, 0, src.stderr)
            row = results.parse_program_output(sink.stdout)
            self.assertEqual(row["metric"], "one_way")
            self.assertEqual(row["payload_bytes"], 288)
            self.assertEqual(row["count"] + row["lost"], 400)
            self.assertGreater(row["count"], 0)
            ProgramTest.check_against_dump(self, row, dump)

    def test_bad_usage(self):
        exe = prog("dds_pingpong")
        for args in ([], ["--role", "x"], ["--role", "ping", "--idle-ms", "0"], ["--role", "sink", "extra"]):
            self.assertEqual(subprocess.run([exe] + args, stderr=subprocess.DEVNULL).returncode, 2, args)


if __name__ == "__main__":
    unittest.main()
