/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Runs the ccomm S-functions without MATLAB: calls their mdl* callbacks the way Simulink
 * does for a fixed-step simulation (mdlInitializeSizes, which checks the parameters in
 * a MEX build; mdlInitializeSampleTimes; mdlStart; mdlOutputs each step in block order;
 * mdlTerminate; mdlRTW for code generation) against a running ccommd, and checks what
 * the blocks output. Usage: simulink_harness NODE (ccommd running harness/signals.xml).
 */
#define _POSIX_C_SOURCE 200809L /* setenv, clock_gettime */
#define S_FUNCTION_NAME harness
#define S_FUNCTION_LEVEL 2
#include <ccomm/ccomm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "simstruc.h"

extern const harness_methods sfun_ccomm_read_mex, sfun_ccomm_write_mex;
extern const harness_methods sfun_ccomm_read_cg, sfun_ccomm_write_cg;

static int passed = 0, failed = 0;
static const char* node;

#define CHECK(cond, ...)                 \
  do {                                   \
    if (cond) {                          \
      passed++;                          \
    } else {                             \
      failed++;                          \
      printf("FAIL %s:%d: ", __FILE__, __LINE__); \
      printf(__VA_ARGS__);               \
      printf("\n");                      \
    }                                    \
  } while (0)

typedef struct {
  SimStruct s;
  const harness_methods* m;
  mxArray p[7];
  real_T in[64], out0[64], out1[64]; /* port buffers; typed ports use them as raw memory */
} block;

static void sleep_ms(int ms) { ccomm_sleep_until(ccomm_now() + (int64_t)ms * 1000000); }

/* The parameters of a block from the masked library (7) or of an older model (4). */
typedef struct {
  const char* name;
  double ts, width;
  const char* node;
  const char* dtype; /* 7-parameter form only */
  double timeout, status;
  int n_params;
} block_params;

/* Sets up a block like Simulink does when a model is updated and started. Returns the
 * error status (NULL = block started). */
static const char* block_start_p(block* b, const harness_methods* m, const block_params* bp) {
  memset(b, 0, sizeof *b);
  b->m = m;
  b->s.path = m->name;
  b->p[0] = (mxArray){1, strlen(bp->name), bp->name, 0.0};
  b->p[1] = (mxArray){0, 1, NULL, bp->ts};
  b->p[2] = (mxArray){0, 1, NULL, bp->width};
  b->p[3] = (mxArray){1, strlen(bp->node), bp->node, 0.0};
  b->p[4] = (mxArray){1, strlen(bp->dtype), bp->dtype, 0.0};
  b->p[5] = (mxArray){0, 1, NULL, bp->timeout};
  b->p[6] = (mxArray){0, 1, NULL, bp->status};
  for (int i = 0; i < 7; i++) b->s.params[i] = &b->p[i];
  b->s.n_params_given = bp->n_params;
  m->initialize_sizes(&b->s);
  if (b->s.error) return b->s.error;
  if (b->s.n_params_expected != -1 && b->s.n_params_expected != bp->n_params) return "parameter count mismatch";
  m->initialize_sample_times(&b->s);
  b->s.in_signal[0] = b->in;
  b->s.out_signal[0] = b->out0;
  b->s.out_signal[1] = b->out1;
  if (m->start) m->start(&b->s);
  return b->s.error;
}

/* A block of a model made before the library: four parameters, double port. */
static const char* block_start(block* b, const harness_methods* m, const char* name, double ts,
                               double width, const char* node_name, int n_params) {
  block_params bp = {name, ts, width, node_name, "double", 0.0, 1.0, n_params};
  return block_start_p(b, m, &bp);
}

/* A masked library block: typed port, timeout, status output on or off. */
static const char* block_start_typed(block* b, const harness_methods* m, const char* name, double width,
                                     const char* dtype, double timeout, int status) {
  block_params bp = {name, 0.01, width, node, dtype, timeout, (double)status, 7};
  return block_start_p(b, m, &bp);
}

/* Model time as a real-time target with a 1 ms base rate would give it: the steps' times
 * follow the wall clock, and the blocks called within one millisecond share a step (and
 * so one clock reading, ccomm_blk_step). */
static double model_time(void) {
  static struct timespec t0;
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  if (t0.tv_sec == 0 && t0.tv_nsec == 0) t0 = now;
  return floor(((double)(now.tv_sec - t0.tv_sec) * 1e3 + (double)(now.tv_nsec - t0.tv_nsec) / 1e6)) / 1e3;
}

static void step(block* b) {
  b->s.t = model_time();
  b->m->outputs(&b->s, 0);
}

static void block_stop(block* b) {
  b->m->terminate(&b->s);
  CHECK(b->s.pwork[0] == NULL, "%s: mdlTerminate left PWork set", b->m->name);
}

static void test_sizes(void) {
  block r, w;
  CHECK(block_start(&r, &sfun_ccomm_read_mex, "sl_array", 0.01, 3, node, 4) == NULL, "read start: %s", r.s.error);
  CHECK(r.s.n_in == 0 && r.s.n_out == 2 && r.s.out_width[0] == 3 && r.s.out_width[1] == 1,
        "read ports: %d in, %d out, widths %d/%d", r.s.n_in, r.s.n_out, r.s.out_width[0], r.s.out_width[1]);
  CHECK(r.s.n_sample_times == 1 && r.s.sample_time[0] == 0.01 && r.s.offset_time[0] == 0.0,
        "read sample time %g", r.s.sample_time[0]);
  CHECK(r.s.n_pwork == 1 && r.s.pwork[0] != NULL, "read PWork not set by mdlStart");
  CHECK(r.s.options & SS_OPTION_CALL_TERMINATE_ON_EXIT, "read: terminate-on-exit option missing");
  block_stop(&r);

  CHECK(block_start(&w, &sfun_ccomm_write_mex, "sl_scalar", -1, 1, node, 4) == NULL, "write start: %s", w.s.error);
  CHECK(w.s.n_in == 1 && w.s.in_width[0] == 1 && w.s.in_direct_feedthrough[0] == 1 && w.s.in_contiguous[0] == 1,
        "write input port set-up");
  CHECK(w.s.n_out == 1 && w.s.out_width[0] == 1, "write output port set-up");
  CHECK(w.s.sample_time[0] == INHERITED_SAMPLE_TIME, "write: -1 must give an inherited sample time");
  block_stop(&w);
}

static void test_scalar_roundtrip(void) {
  block w, r;
  const char* e1 = block_start(&w, &sfun_ccomm_write_mex, "sl_scalar", 0.01, 1, node, 4);
  const char* e2 = block_start(&r, &sfun_ccomm_read_mex, "sl_scalar", 0.01, 1, node, 4);
  CHECK(e1 == NULL && e2 == NULL, "start: %s / %s", e1 ? e1 : "-", e2 ? e2 : "-");
  if (e1 || e2) return;
  int ok = 1;
  for (int k = 0; k < 50; k++) {
    w.in[0] = 0.5 * k - 3.25;
    step(&w); /* sorted order: the writer runs before the reader */
    step(&r);
    if (w.out0[0] != 0.0 || r.out0[0] != w.in[0] || r.out1[0] != CCOMM_FRESH) {
      printf("step %d: write result %g, read %g status %g (wrote %g)\n", k, w.out0[0], r.out0[0], r.out1[0], w.in[0]);
      ok = 0;
      break;
    }
  }
  CHECK(ok, "50 steps of write then read give the written value, fresh");
  /* No more writes: after stale_after_ms (100) the read block says stale. */
  sleep_ms(250);
  step(&r);
  CHECK(r.out1[0] == CCOMM_STALE, "status after 250 ms without writes: %g (want %d)", r.out1[0], CCOMM_STALE);
  block_stop(&w);
  block_stop(&r);
}

static void test_array_conversion(void) {
  block w, r;
  const char* e1 = block_start(&w, &sfun_ccomm_write_mex, "sl_array", 0.01, 3, node, 4);
  const char* e2 = block_start(&r, &sfun_ccomm_read_mex, "sl_array", 0.01, 3, node, 4);
  CHECK(e1 == NULL && e2 == NULL, "start: %s / %s", e1 ? e1 : "-", e2 ? e2 : "-");
  if (e1 || e2) return;
  w.in[0] = 1.4;
  w.in[1] = -2.6;
  w.in[2] = 3e10; /* int32 signal: rounded and saturated, never wrapped */
  step(&w);
  step(&r);
  CHECK(w.out0[0] == 0.0, "array write result %g", w.out0[0]);
  CHECK(r.out1[0] == CCOMM_FRESH && r.out0[0] == 1.0 && r.out0[1] == -3.0 && r.out0[2] == 2147483647.0,
        "int32[3] read back %g %g %g status %g", r.out0[0], r.out0[1], r.out0[2], r.out1[0]);
  w.in[2] = NAN;
  step(&w);
  step(&r);
  CHECK(r.out0[2] == 0.0, "NaN written to int32 reads back as %g, want 0", r.out0[2]);
  block_stop(&w);
  block_stop(&r);
}

static void test_events(void) {
  block w, r;
  const char* e1 = block_start(&w, &sfun_ccomm_write_mex, "sl_event", 0.01, 1, node, 4);
  const char* e2 = block_start(&r, &sfun_ccomm_read_mex, "sl_event", 0.01, 1, node, 4);
  CHECK(e1 == NULL && e2 == NULL, "start: %s / %s", e1 ? e1 : "-", e2 ? e2 : "-");
  if (e1 || e2) return;
  w.in[0] = 1.0;
  step(&w);
  step(&r);
  CHECK(r.out1[0] == CCOMM_FRESH && r.out0[0] == 1.0, "first event: %g status %g", r.out0[0], r.out1[0]);
  step(&w); /* unchanged value: no new event */
  step(&r);
  CHECK(r.out1[0] == CCOMM_EMPTY && r.out0[0] == 1.0, "unchanged input: %g status %g (want hold, %d)",
        r.out0[0], r.out1[0], CCOMM_EMPTY);
  w.in[0] = 2.0;
  step(&w);
  w.in[0] = 3.0;
  step(&w); /* two events before the reader's step: it sees the newest */
  step(&r);
  CHECK(r.out1[0] == CCOMM_FRESH && r.out0[0] == 3.0, "two events in one step: %g status %g", r.out0[0], r.out1[0]);
  block_stop(&w);
  block_stop(&r);
}

static void test_errors(void) {
  block b;
  const char* e;
  e = block_start(&b, &sfun_ccomm_read_mex, "no_such_signal", 0.01, 1, node, 4);
  CHECK(e && strstr(e, "no signal 'no_such_signal'"), "unknown signal: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start(&b, &sfun_ccomm_read_mex, "sl_array", 0.01, 2, node, 4);
  CHECK(e && strstr(e, "3 element(s)"), "width mismatch: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start(&b, &sfun_ccomm_write_mex, "sl_remote", 0.01, 1, node, 4);
  CHECK(e && strstr(e, "produced by node 'other'"), "write of a remote signal: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start(&b, &sfun_ccomm_read_mex, "sl_scalar", 0.01, 1, "no_such_node", 4);
  CHECK(e && strstr(e, "cannot attach"), "unknown node: %s", e ? e : "(started)");
  if (!e) block_stop(&b);
  e = block_start(&b, &sfun_ccomm_read_mex, "sl_scalar", 0.0, 1, node, 4);
  CHECK(e && strstr(e, "sample time"), "sample time 0: %s", e ? e : "(started)");
  e = block_start(&b, &sfun_ccomm_write_mex, "sl_scalar", 0.01, 1.5, node, 4);
  CHECK(e && strstr(e, "width"), "width 1.5: %s", e ? e : "(started)");
  e = block_start(&b, &sfun_ccomm_read_mex, "", 0.01, 1, node, 4);
  CHECK(e && strstr(e, "signal name"), "empty name: %s", e ? e : "(started)");
  e = block_start(&b, &sfun_ccomm_read_mex, "sl_scalar", 0.01, 1, node, 3);
  CHECK(e && strstr(e, "3 parameters; expected 7"), "3 parameters: %s", e ? e : "(started)");

  /* A read block on a signal from another node that never arrived: status never. */
  e = block_start(&b, &sfun_ccomm_read_mex, "sl_remote", 0.01, 1, node, 4);
  CHECK(e == NULL, "read of a remote signal: %s", e ? e : "");
  if (!e) {
    step(&b);
    CHECK(b.out1[0] == CCOMM_NEVER, "remote signal never received: status %g", b.out1[0]);
    block_stop(&b);
  }
}

static void test_rtw(void) {
  block b;
  const char* e = block_start(&b, &sfun_ccomm_write_mex, "sl_array", 0.01, 3, "", 4);
  CHECK(e == NULL, "start: %s", e ? e : "");
  if (e) return;
  CHECK(b.m->rtw != NULL, "mdlRTW compiled in the MEX build");
  b.m->rtw(&b.s);
  CHECK(strcmp(b.s.rtw, "SignalName=\"sl_array\";Node=\"\";Width=3;DataType=0;Timeout=0;StatusOutput=1;") == 0,
        "mdlRTW wrote %s", b.s.rtw);
  block_stop(&b);
}

/* The same S-functions compiled as for non-inlined generated code (cg_sfun.h). */
static void test_codegen_build(void) {
  block w, r;
  const char* e1 = block_start(&w, &sfun_ccomm_write_cg, "sl_scalar", 0.01, 1, node, 4);
  const char* e2 = block_start(&r, &sfun_ccomm_read_cg, "sl_scalar", 0.01, 1, node, 4);
  CHECK(e1 == NULL && e2 == NULL, "cg start: %s / %s", e1 ? e1 : "-", e2 ? e2 : "-");
  if (e1 || e2) return;
  CHECK(sfun_ccomm_read_cg.check_parameters == NULL && sfun_ccomm_read_cg.rtw == NULL,
        "MEX-only callbacks must not be in the code-generation build");
  w.in[0] = 42.0;
  step(&w);
  step(&r);
  CHECK(r.out0[0] == 42.0 && r.out1[0] == CCOMM_FRESH, "cg build read %g status %g", r.out0[0], r.out1[0]);
  block_stop(&w);
  block_stop(&r);
}

#include "harness_typed.c"

int main(int argc, char** argv) {
  ccomm_client* c = NULL;
  node = argc > 1 ? argv[1] : "sim";
  /* Blocks with node '' attach to $CCOMM_NODE: point it at the test node. */
  setenv("CCOMM_NODE", node, 1);
  /* Wait for ccommd's segment (started in parallel by the test script). */
  for (int i = 0; i < 200 && ccomm_open(node, 0, &c) != 0; i++) sleep_ms(50);
  if (!c) {
    printf("FAIL no ccomm segment for node %s\n", node);
    return 1;
  }
  ccomm_close(c);
  test_sizes();
  test_scalar_roundtrip();
  test_array_conversion();
  test_events();
  test_errors();
  test_rtw();
  test_codegen_build();
  test_typed_ports();
  test_typed_options();
  printf("%d passed, %d failed\n", passed, failed);
  return failed ? 1 : 0;
}
