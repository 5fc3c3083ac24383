# SPDX-License-Identifier: Apache-2.0
"""Control step for test_batch.py, through libccomm's C API (ctypes): a CCOMM_OPEN_BATCH
handle writes bA, then a second, plain handle writes cC (its doorbell wakes ccommd in the
middle of the step), then the batch handle writes bB and flushes. N cycles. With
PAUSE_US 0 the steps follow each other back to back (ccommd lags behind them).

    python3 batch_writer.py LIBCCOMM NODE CYCLES [PAUSE_US (default 1000)]
"""
import ctypes
import sys
import time

lib = ctypes.CDLL(sys.argv[1])
node, cycles = sys.argv[2].encode(), int(sys.argv[3])
pause = (float(sys.argv[4]) if len(sys.argv) > 4 else 1000.0) / 1e6  # per step: 30 % mid-step, 70 % after
lib.ccomm_write_double.argtypes = [ctypes.c_void_p, ctypes.c_int32, ctypes.c_double]
lib.ccomm_flush.argtypes = [ctypes.c_void_p]
lib.ccomm_find.argtypes = [ctypes.c_void_p, ctypes.c_char_p]


def open_handle(flags):
    h = ctypes.c_void_p()
    r = lib.ccomm_open(node, ctypes.c_uint32(flags), ctypes.byref(h))
    if r != 0:
        sys.exit("ccomm_open: %d" % r)
    return h


batch, plain = open_handle(0x2), open_handle(0)  # CCOMM_OPEN_BATCH, default
a, b, c = (lib.ccomm_find(batch, n) for n in (b"bA", b"bB", b"cC"))
cc = lib.ccomm_find(plain, b"cC")
for i in range(1, cycles + 1):
    assert lib.ccomm_write_double(batch, a, float(i)) == 0
    assert lib.ccomm_write_double(plain, cc, float(i)) == 0  # rings the doorbell now
    if pause:
        time.sleep(0.3 * pause)  # ccommd wakes and sends cC while the step is still open
    assert lib.ccomm_write_double(batch, b, float(i)) == 0
    assert lib.ccomm_flush(batch) == 0
    if pause:
        time.sleep(0.7 * pause)
print("wrote", cycles)
