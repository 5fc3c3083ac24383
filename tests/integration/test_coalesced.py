# SPDX-License-Identifier: Apache-2.0
"""Every state write is either sent or counted coalesced (writes == tx + coalesced), also
for values written before ccommd sent the first one, and values a writer replaced before
ccommd looked still leave while the cell's slots hold them (send_path.cpp, CatchUp): a
NO_DOORBELL handle writes twice before ccommd looks (it only looks at its next wake-up,
within heartbeat_ms): both are sent; then six times: the last four are sent (a state
keeps four copies), the two before them are counted coalesced, and the planner counts
exactly that gap as lost. (tests/manyboards found writes == tx + coalesced + 1.)"""
import os
import subprocess
import sys

from harness import BUILD, NodePair, python_env, signal_stats, wait_for

CONFIG = """<?xml version="1.0"?>
<ccomm version="1">
  <network udp_port="47812"/>
  <node name="control" interface="eth0" ip="10.42.0.1" transport="udp"/>
  <node name="planner" interface="eth0" ip="10.42.0.2" transport="udp"/>
  <signal name="x" type="double" producer="control" consumers="planner"/>
</ccomm>
"""
WRITER = """
import ctypes, sys, time
lib = ctypes.CDLL(sys.argv[1])
lib.ccomm_write_double.argtypes = [ctypes.c_void_p, ctypes.c_int32, ctypes.c_double]
lib.ccomm_find.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
h = ctypes.c_void_p()
assert lib.ccomm_open(b"control", ctypes.c_uint32(0x1), ctypes.byref(h)) == 0  # CCOMM_OPEN_NO_DOORBELL
x = lib.ccomm_find(h, b"x")
lib.ccomm_write_double(h, x, 1.0); lib.ccomm_write_double(h, x, 2.0)  # both before ccommd looks
time.sleep(0.3)                                                        # > heartbeat_ms: 2 was sent
for v in range(3, 9):
    lib.ccomm_write_double(h, x, float(v))                             # 3..8 before ccommd looks
time.sleep(0.3)
"""


def test_values_replaced_before_the_first_send_count_as_coalesced(tmp_path):
    cfg = tmp_path / "coalesced.xml"
    cfg.write_text(CONFIG)
    with NodePair(config=str(cfg)) as pair:
        pair.start("control")
        pair.start("planner")
        w = subprocess.run(pair.exec_prefix("control") + [sys.executable, "-c", WRITER,
                                                          os.path.join(BUILD, "lib", "libccomm.so")],
                           env=python_env(pair.env), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           timeout=30)
        assert w.returncode == 0, w.stdout
        assert wait_for(lambda: signal_stats(pair.stats("planner"), "x")["rx"] >= 6, 5) is not None
        prod = signal_stats(pair.stats("control"), "x")
        cons = signal_stats(pair.stats("planner"), "x")
        last = pair.echo_once("planner", "x")
    assert prod["writes"] == 8, prod
    assert (prod["tx"], prod["coalesced"]) == (6, 2), prod  # 1, 2, then 5..8 sent; 3, 4 gone
    assert (cons["rx"], cons["lost"]) == (6, 2), cons       # the gap 2 -> 5, exactly
    assert float(last[0]) == 8.0, last
