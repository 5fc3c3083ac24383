# SPDX-License-Identifier: Apache-2.0
"""Tests of scripts/bench's own logic (run from scripts/):

    CCOMM_BUILD_DIR=<build tree> python3 -m unittest -v benchlib.test_bench

The configuration tests need ccommd (skipped when it is not built).
"""

import os
import subprocess
import tempfile
import unittest

from . import callgrind, ccomm, procs, report, results, suite

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


def _ccommd():
    for d in (os.environ.get("CCOMM_BUILD_DIR"), os.path.join(REPO, "build", "perf"), os.path.join(REPO, "build", "release")):
        if d and os.path.exists(os.path.join(d, "bin", "ccommd")):
            return os.path.join(d, "bin", "ccommd")
    return None


class ConfigTest(unittest.TestCase):
    def check(self, text):
        exe = _ccommd()
        if not exe:
            self.skipTest("ccommd not built")
        with tempfile.NamedTemporaryFile("w", suffix=".xml") as f:
            f.write(text)
            f.flush()
            cp = subprocess.run([exe, "--check", f.name], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.assertEqual(cp.returncode, 0, cp.stdout)
        return cp.stdout

    def test_pair_configs_are_valid(self):
        ns = procs.NetnsPair("x")
        for periodic in (0, 100, 10000):
            for transport in ("raw", "udp"):
                text = ccomm.pair_config(("control", "planner"), ccomm.SETUP_A2B, ccomm.SETUP_B2A, transport, ns,
                                         periodic, 80, (0, 1))
                out = self.check(text)
                self.assertIn("2 nodes, 45 signals", out)
                self.assertEqual(text.count('rate_hz="%g"' % periodic), 45 if periodic else 0)

    def test_local_config_is_valid(self):
        out = self.check(ccomm.local_config(80, 0))
        # 36 states + 1 event for ccomm-latency, and ccomm_pingpong's three pairs.
        self.assertIn("1 nodes, %d signals" % (37 + 2 * len(ccomm.PINGPONG)), out)

    def test_setup_names_match_default_config(self):
        with open(os.path.join(REPO, "dist", "signals.xml")) as f:
            text = f.read()
        for name in ccomm.SETUP_A2B + ccomm.SETUP_B2A:
            self.assertIn('name="%s"' % name, text)


class CallgrindTest(unittest.TestCase):
    def test_calls_summed_over_call_sites(self):
        text = "\n".join([
            "events: Ir", "fl=(1) a.cpp", "fn=(1) main", "10 5",
            "cfn=(2) ccomm::Daemon::HandleFrame(unsigned char const*)", "calls=3 20", "11 300",
            "fn=(3) other", "cfn=(2)", "calls=1 20", "+2 150",
            "fn=(2)", "20 100", "totals: 555", ""])
        with tempfile.NamedTemporaryFile("w", suffix=".cg") as f:
            f.write(text)
            f.flush()
            calls = callgrind.inclusive_calls(f.name)
            self.assertEqual(callgrind.total_ir(f.name), 555)
        self.assertEqual(calls["ccomm::Daemon::HandleFrame(unsigned char const*)"], [4, 450])
        self.assertEqual(callgrind.per_call(calls, [("rx", "HandleFrame(")]), [("rx", 4, 112.5)])


class MergeTest(unittest.TestCase):
    def test_halves_join(self):
        with tempfile.TemporaryDirectory() as d:
            os.makedirs(os.path.join(d, "raw"))
            rows = []
            for i, vals in enumerate(([10, 20], [30, 40, 50]), 1):
                name = "ccomm_x" + suite.REPEAT % i
                with open(os.path.join(d, "raw", name + ".tsv"), "w") as f:
                    f.write("".join("%d\t%d\n" % (k, v) for k, v in enumerate(vals)))
                rows.append(results.row_from_samples(name, "raw", 8, 1000, vals, i, raw="raw/%s.tsv" % name,
                                                     sent=10 * i, wire={"data_frames": 10 * i, "frames_lost": 0},
                                                     values=10 * i, cpu_ns_per_value=1000 * i,
                                                     cpu_ns=10000 * i * i, cpu_apps_ns=4000 * i * i,
                                                     cpu_daemons_ns=6000 * i * i, window_ns=10 ** 9,
                                                     cpu_daemon_threads={"send": {"run_ns": 100 * i,
                                                                                  "times_run": i}}))
            rows.append(results.row_from_samples("other", "raw", 8, 1000, [1], 0))
            out = suite.merge_repeats(rows, d)
            self.assertEqual([r["name"] for r in out], ["ccomm_x", "other"])
            m = out[0]
            self.assertEqual((m["count"], m["lost"], m["min_ns"], m["max_ns"], m["p50_ns"]), (5, 3, 10, 50, 30))
            self.assertEqual(m["sent"], 30)
            self.assertEqual(m["frames_per_cycle"], 1.0)
            # CPU per value over both halves, weighted by their values: (10*1000 + 20*2000) / 30
            self.assertEqual((m["cpu_ns_per_value"], m["rep_cpu_ns_per_value"], m["values"]), (1667, [1000, 2000], 30))
            # The counters behind it summed, so that counter / values is per value over both.
            self.assertEqual((m["cpu_ns"], m["cpu_apps_ns"], m["cpu_daemons_ns"], m["window_ns"]),
                             (50000, 20000, 30000, 2 * 10 ** 9))
            self.assertEqual(round(m["cpu_ns"] / m["values"]), m["cpu_ns_per_value"])
            self.assertEqual(m["cpu_daemon_threads"], {"send": {"run_ns": 300, "times_run": 3}})
            self.assertEqual(len(results.load_raw(os.path.join(d, m["raw"]))), 5)


class ReportTest(unittest.TestCase):
    def rows(self, ccomm_p50, floor_p50):
        mk = results.row_from_samples
        return [
            dict(mk("net_raw_oneway_1khz_p8", "raw", 8, 1000, [floor_p50], 0, metric="one_way"), section="b2b"),
            dict(mk("ccomm_raw_oneway_block_1khz_p8", "raw", 8, 1000, [ccomm_p50], 0, metric="one_way"),
                 section="b2b", style="block"),
            dict(mk("thesis_setup_event_10khz_a2b", "raw", 288, 10000, [50000], 0), section="thesis", exp="setup",
                 mode="event", direction="a2b", style="block", frames_per_cycle=1.0, sent=100,
                 wire={"frames_lost": 0}, wire_signals_lost=0),
        ]

    def status(self, checks, prefix):
        return next(c["status"] for c in checks if c["text"].startswith(prefix))

    def test_targets(self):
        meta = {"date": "d", "command": "scripts/bench", "loadavg_start": ["1", "1", "1"]}
        text, checks = report.render(self.rows(12000, 10000), meta, [], "/tmp", [])
        self.assertEqual(self.status(checks, "board->board raw one-way, 8 B"), "met")
        self.assertEqual(self.status(checks, "setup-simulation event"), "met")
        self.assertEqual(self.status(checks, "10 kHz, event-driven: no frame"), "met")
        self.assertIn("1.20x", text)
        text, checks = report.render(self.rows(14000, 10000), meta, [], "/tmp", [])
        self.assertEqual(self.status(checks, "board->board raw one-way, 8 B"), "MISSED")
        self.assertIn("over by 7.7%", text)
        self.assertNotIn(REPO + os.sep, text)


if __name__ == "__main__":
    unittest.main()


class PeersTest(unittest.TestCase):
    """The peer comparison (issue 30): the throughput sweep and the target lines."""

    def test_sweep_stops_at_first_lossy_step(self):
        from . import peers
        seen = []

        def measure(rate):
            seen.append(rate)
            lost = 0 if rate <= 2000 else 50
            return {"rate_hz": rate, "count": 1000 - lost, "lost": lost, "p50_ns": 1000, "rx_values_per_s": rate}
        row = peers.sweep(measure, peers.THROUGHPUT_RATES)
        self.assertEqual(seen, [1000, 2000, 5000])
        self.assertEqual(row["values_per_s_lossfree"], 2000)
        self.assertEqual(row["values_per_s_at_loss"], 5000)
        # Within the loss limit counts as without loss; beyond it does not.
        self.assertFalse(peers.lossy({"count": 10000, "lost": 10}))
        self.assertTrue(peers.lossy({"count": 10000, "lost": 11}))
        self.assertTrue(peers.lossy({"count": 0, "lost": 0}))

    def test_peer_targets_judge_and_name_missing_rows(self):
        from . import formatting, peers, targets

        def row(name, p50, cpu):
            return {"name": name, "p50_ns": p50, "cpu_ns_per_value": cpu}
        R = formatting.Rows([row("ccomm_udp_oneway_block_1khz_p8_vs_dds", 50000, 90000),
                             row("dds_be_oneway_1khz_p8", 60000, 80000)])
        cks = peers.checks(R, targets._check)
        by = {(c["rows"][1], c["rows"][2]): c for c in cks if "rows" in c}
        self.assertEqual(by[("dds_be_oneway_1khz_p8", "p50_ns")]["status"], "met")
        miss = by[("dds_be_oneway_1khz_p8", "cpu_ns_per_value")]
        self.assertEqual(miss["status"], "MISSED")
        self.assertIn("over by 10.00 µs", miss["detail"])
        # Every peer row without its data is a line of its own saying what is missing.
        absent = [c for c in cks if "zenoh_udp_oneway_1khz_p8" in c["text"]]
        self.assertEqual(len(absent), 2)
        self.assertTrue(all(c["status"] == "n/a" and "`zenoh_udp_oneway_1khz_p8`" in c["detail"] for c in absent))
