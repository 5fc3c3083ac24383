/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Checks a running PD controller (the generated 20-sim task or the 4C component harness)
 * through ccomm: plays the plant by writing position/velocity on node ctrl, and checks
 * setpoint = ccomm_ok * (kp * (reference - position) - kd * velocity) and that
 * error_integral grows at the rate of the error, i.e. that the model runs periodically.
 * Usage: pd_check [NODE [KP]]. Exit 0 if every check passes.
 */
#define _POSIX_C_SOURCE 200809L
#include <ccomm/ccomm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double kp = 2.0; /* argv[2] overrides: the task was started with --param kp=... */
static const double kd = 0.5, reference = 1.0;
static ccomm_client* c;
static ccomm_signal s_pos, s_vel, s_sp, s_int;
static int failures = 0;

static double now_s(void) { return 1e-9 * (double)ccomm_now(); }

static void sleep_s(double s) { ccomm_sleep_until(ccomm_now() + (int64_t)(s * 1e9)); }

/* Writes the plant outputs at 200 Hz for `seconds` (or only sleeps if write == 0). */
static void play(double pos, double vel, double seconds, int write) {
  double end = now_s() + seconds;
  while (now_s() < end) {
    if (write) {
      int r1 = ccomm_write_double(c, s_pos, pos), r2 = ccomm_write_double(c, s_vel, vel);
      if (r1 != 0 || r2 != 0) {
        printf("FAIL write position/velocity: %s\n", ccomm_strerror(r1 ? r1 : r2));
        failures++;
        return;
      }
    }
    sleep_s(0.005);
  }
}

static void expect_setpoint(const char* what, double want) {
  double sp = NAN;
  ccomm_info info;
  int r = ccomm_read_double(c, s_sp, &sp, &info);
  int ok = r >= 0 && r != CCOMM_NEVER && fabs(sp - want) < 1e-9;
  printf("%s %s: setpoint=%.6f expected %.6f (status %d, seq %llu, age %.1f ms)\n",
         ok ? "PASS" : "FAIL", what, sp, want, r, (unsigned long long)info.seq, info.age_ns / 1e6);
  if (!ok) failures++;
}

static double read_int(uint64_t* seq) {
  double v = NAN;
  ccomm_info info;
  ccomm_read_double(c, s_int, &v, &info);
  if (seq) *seq = info.seq;
  return v;
}

int main(int argc, char** argv) {
  const char* node = argc > 1 ? argv[1] : "ctrl";
  if (argc > 2) kp = atof(argv[2]);
  double deadline = now_s() + 10.0;
  int r;
  /* ccommd and the controller start in parallel: wait for the segment and the first
   * controller output. */
  while ((r = ccomm_open(node, 0, &c)) != 0 && now_s() < deadline) sleep_s(0.05);
  if (r != 0) {
    printf("FAIL ccomm_open(%s): %s\n", node, ccomm_strerror(r));
    return 1;
  }
  s_pos = ccomm_find(c, "position");
  s_vel = ccomm_find(c, "velocity");
  s_sp = ccomm_find(c, "setpoint");
  s_int = ccomm_find(c, "error_integral");
  if (s_pos < 0 || s_vel < 0 || s_sp < 0 || s_int < 0) {
    printf("FAIL signals position/velocity/setpoint/error_integral not all configured\n");
    return 1;
  }
  for (;;) {
    double v;
    if (ccomm_read_double(c, s_sp, &v, NULL) == CCOMM_FRESH) break;
    if (now_s() > deadline) {
      printf("FAIL the controller never wrote setpoint\n");
      return 1;
    }
    sleep_s(0.02);
  }

  /* 1. Fresh inputs: the control law, exactly. */
  play(0.2, 0.1, 0.4, 1);
  expect_setpoint("fresh inputs", kp * (reference - 0.2) - kd * 0.1);

  /* 2. The integral of the error advances with time: the model steps periodically. */
  uint64_t seq0, seq1;
  double t0 = now_s(), i0 = read_int(&seq0);
  play(0.2, 0.1, 0.6, 1);
  double t1 = now_s(), i1 = read_int(&seq1);
  double rate = (i1 - i0) / (t1 - t0), want = reference - 0.2;
  int rate_ok = rate > 0.5 * want && rate < 1.2 * want;
  printf("%s integral rate %.3f /s, expected %.3f /s (-50%%..+20%% for timing); %llu outputs in %.2f s\n",
         rate_ok ? "PASS" : "FAIL", rate, want, (unsigned long long)(seq1 - seq0), t1 - t0);
  if (!rate_ok) failures++;

  /* 3. New inputs. */
  play(1.5, -0.2, 0.3, 1);
  expect_setpoint("changed inputs", kp * (reference - 1.5) - kd * -0.2);

  /* 4. Inputs stop (stale after 100 ms): ccomm_ok drops, the model outputs 0. */
  play(0, 0, 0.5, 0);
  expect_setpoint("stale inputs", 0.0);
  uint64_t seq2;
  read_int(&seq2);
  play(0, 0, 0.1, 0);
  uint64_t seq3;
  read_int(&seq3);
  int running = seq3 > seq2;
  printf("%s controller keeps running while inputs are stale (%llu new outputs in 0.1 s)\n",
         running ? "PASS" : "FAIL", (unsigned long long)(seq3 - seq2));
  if (!running) failures++;

  /* 5. Inputs come back. */
  play(0.2, 0.1, 0.3, 1);
  expect_setpoint("recovered inputs", kp * (reference - 0.2) - kd * 0.1);

  ccomm_close(c);
  printf("%d passed, %d failed\n", 6 - failures, failures);
  return failures ? 1 : 0;
}
