/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Harness checks of the masked library blocks (seven parameters): typed ports (int32,
 * uint32, boolean, single; arrays), the status output switched off, the read timeout,
 * what mdlRTW hands to the TLC files, and the parameter errors. Included by harness.c,
 * whose block helpers and CHECK it uses.
 */
#include <stdint.h>

/* Write then read one typed array through a write block and a read block; the read
 * port must hold exactly `want` (bytes of `n` elements of `size`). */
static void typed_roundtrip(const char* sig, const char* dtype, DTypeId id, int n, size_t size,
                            const void* write, const void* want, const harness_methods* wm,
                            const harness_methods* rm) {
  block w, r;
  const char* e1 = block_start_typed(&w, wm, sig, n, dtype, 0.0, 1);
  const char* e2 = block_start_typed(&r, rm, sig, n, dtype, 0.0, 1);
  CHECK(e1 == NULL && e2 == NULL, "%s %s start: %s / %s", dtype, sig, e1 ? e1 : "-", e2 ? e2 : "-");
  if (e1 || e2) return;
  CHECK(w.s.in_dtype[0] == id && w.s.in_width[0] == n && r.s.out_dtype[0] == id && r.s.out_width[0] == n,
        "%s ports: write in type %d width %d, read out type %d width %d", dtype, w.s.in_dtype[0],
        w.s.in_width[0], r.s.out_dtype[0], r.s.out_width[0]);
  CHECK(r.s.out_dtype[1] == SS_DOUBLE && w.s.out_dtype[0] == SS_DOUBLE, "%s: status ports are double", dtype);
  memcpy(w.in, write, (size_t)n * size);
  memset(r.out0, 0xA5, sizeof r.out0);
  step(&w);
  step(&r);
  CHECK(w.out0[0] == 0.0 && r.out1[0] == CCOMM_FRESH, "%s write result %g, read status %g", dtype, w.out0[0], r.out1[0]);
  CHECK(memcmp(r.out0, want, (size_t)n * size) == 0, "%s[%d] %s: read port differs from what was written", dtype, n, sig);
  block_stop(&w);
  block_stop(&r);
}

static void test_typed_ports(void) {
  const int32_t i32[3] = {-5, 7, 2147483647};
  const uint32_t u32[2] = {0u, 4294967295u};
  const unsigned char b_in[4] = {1, 0, 2, 1}, b_want[4] = {1, 0, 1, 1}; /* 2 is true */
  const float f32[2] = {1.5f, -0.25f};
  typed_roundtrip("sl_array", "int32", SS_INT32, 3, 4, i32, i32, &sfun_ccomm_write_mex, &sfun_ccomm_read_mex);
  typed_roundtrip("sl_u32", "uint32", SS_UINT32, 2, 4, u32, u32, &sfun_ccomm_write_mex, &sfun_ccomm_read_mex);
  typed_roundtrip("sl_bool", "boolean", SS_BOOLEAN, 4, 1, b_in, b_want, &sfun_ccomm_write_mex, &sfun_ccomm_read_mex);
  typed_roundtrip("sl_f32", "single", SS_SINGLE, 2, 4, f32, f32, &sfun_ccomm_write_mex, &sfun_ccomm_read_mex);
  /* The code-generation build of the same S-functions. */
  typed_roundtrip("sl_u32", "uint32", SS_UINT32, 2, 4, u32, u32, &sfun_ccomm_write_cg, &sfun_ccomm_read_cg);
  /* A double port on a typed signal still converts (rounding, as the 4-parameter form). */
  {
    const double d[2] = {1.6, 7.0};
    const uint32_t want[2] = {2u, 7u};
    block w, r;
    const char* e1 = block_start_typed(&w, &sfun_ccomm_write_mex, "sl_u32", 2, "double", 0.0, 1);
    const char* e2 = block_start_typed(&r, &sfun_ccomm_read_mex, "sl_u32", 2, "uint32", 0.0, 1);
    CHECK(e1 == NULL && e2 == NULL, "double->uint32 start: %s / %s", e1 ? e1 : "-", e2 ? e2 : "-");
    if (!e1 && !e2) {
      memcpy(w.in, d, sizeof d);
      step(&w);
      step(&r);
      uint32_t got[2];
      memcpy(got, r.out0, sizeof got);
      CHECK(memcmp(got, want, sizeof want) == 0, "double port written to uint32: read %u %u", got[0], got[1]);
      block_stop(&w);
      block_stop(&r);
    }
  }
}

static void test_typed_options(void) {
  block w, r, b;
  const char* e;
  /* Status output off: the read block has only its value port, the write block none. */
  e = block_start_typed(&r, &sfun_ccomm_read_mex, "sl_scalar", 1, "double", 0.0, 0);
  CHECK(e == NULL && r.s.n_out == 1, "read without status: %s, %d output(s)", e ? e : "started", r.s.n_out);
  const char* e2 = block_start_typed(&w, &sfun_ccomm_write_mex, "sl_scalar", 1, "double", 0.0, 0);
  CHECK(e2 == NULL && w.s.n_out == 0, "write without status: %s, %d output(s)", e2 ? e2 : "started", w.s.n_out);
  if (!e && !e2) {
    r.out1[0] = -1234.0; /* must stay untouched */
    w.in[0] = 9.5;
    step(&w);
    step(&r);
    CHECK(r.out0[0] == 9.5 && r.out1[0] == -1234.0, "read without status: value %g, port 2 memory %g", r.out0[0], r.out1[0]);
  }
  if (!e) block_stop(&r);
  if (!e2) block_stop(&w);

  /* Timeout 0.2 s on sl_f32 (stale_after_ms 1000 in signals.xml): the block says stale
   * after 400 ms without writes, keeping the last value; the configuration alone would
   * still say fresh. */
  const float v[2] = {3.0f, 4.0f};
  e = block_start_typed(&w, &sfun_ccomm_write_mex, "sl_f32", 2, "single", 0.0, 1);
  e2 = block_start_typed(&r, &sfun_ccomm_read_mex, "sl_f32", 2, "single", 0.2, 1);
  CHECK(e == NULL && e2 == NULL, "timeout blocks: %s / %s", e ? e : "-", e2 ? e2 : "-");
  if (!e && !e2) {
    memcpy(w.in, v, sizeof v);
    step(&w);
    step(&r);
    CHECK(r.out1[0] == CCOMM_FRESH, "timeout: right after the write status %g", r.out1[0]);
    sleep_ms(400);
    step(&r);
    CHECK(r.out1[0] == CCOMM_STALE && memcmp(r.out0, v, sizeof v) == 0,
          "timeout 0.2 s, value 400 ms old: status %g (want %d), value kept %d", r.out1[0], CCOMM_STALE,
          memcmp(r.out0, v, sizeof v) == 0);
    block b2;
    const char* e3 = block_start_typed(&b2, &sfun_ccomm_read_mex, "sl_f32", 2, "single", 0.0, 1);
    if (!e3) {
      step(&b2);
      CHECK(b2.out1[0] == CCOMM_FRESH, "without a block timeout the same value is fresh: %g", b2.out1[0]);
      block_stop(&b2);
    }
  }
  if (!e) block_stop(&w);
  if (!e2) block_stop(&r);

  /* What mdlRTW gives the TLC files for a typed block. */
  e = block_start_typed(&b, &sfun_ccomm_read_mex, "sl_u32", 2, "uint32", 0.25, 0);
  CHECK(e == NULL, "rtw typed start: %s", e ? e : "");
  if (!e) {
    b.m->rtw(&b.s);
    CHECK(strcmp(b.s.rtw, "SignalName=\"sl_u32\";Node=\"sim\";Width=2;DataType=7;Timeout=0.25;StatusOutput=0;") == 0,
          "typed mdlRTW wrote %s", b.s.rtw);
    block_stop(&b);
  }

  /* Parameter and type errors, each with its reason. */
  e = block_start_typed(&b, &sfun_ccomm_read_mex, "sl_u32", 2, "int32", 0.0, 1);
  CHECK(e && strstr(e, "signal 'sl_u32' is uint32; a port of type int32 needs signal type int32"), "int32 port on uint32 signal: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start_typed(&b, &sfun_ccomm_write_mex, "sl_scalar", 1, "boolean", 0.0, 1);
  CHECK(e && strstr(e, "is double; a port of type boolean"), "boolean port on double signal: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start_typed(&b, &sfun_ccomm_read_mex, "sl_scalar", 1, "int16", 0.0, 1);
  CHECK(e && strstr(e, "parameter 5 (data type)"), "data type int16: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start_typed(&b, &sfun_ccomm_read_mex, "sl_scalar", 1, "double", -1.0, 1);
  CHECK(e && strstr(e, "parameter 6 (timeout)"), "timeout -1: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start_typed(&b, &sfun_ccomm_read_mex, "sl_scalar", 1, "double", 0.0, 2);
  CHECK(e && strstr(e, "parameter 7 (status output)"), "status output 2: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
}
