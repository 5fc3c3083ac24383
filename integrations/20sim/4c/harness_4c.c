/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Stands in for 20-sim 4C running a model with the generated ccomm component: calls the
 * component in the order 4C's generated task does (initialize; each period input,
 * model, output; terminate) around the same PD law as example/PDController_tokens.xml.
 * Runs until SIGINT/SIGTERM; the port numbers come from the generated ccomm_4c.h.
 */
#define _POSIX_C_SOURCE 200809L
#include <ccomm/ccomm.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <stdint.h>

#include "ccomm_4c.h"

static volatile sig_atomic_t stop = 0;
static void on_signal(int s) {
  (void)s;
  stop = 1;
}

int main(void) {
  const double h = 0.002, kp = 2.0, kd = 0.5, reference = 1.0;
  double integral = 0.0;
  unsigned long cycles = 0, not_fresh = 0;
  struct sigaction sa;
  int64_t next;
  int r;

  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);

  r = ccomm4c_initialize();
  if (r != 0) return 1;
  next = ccomm_now();
  while (!stop) {
    double pos, vel, ok, error;
    r = ccomm4c_input();
    if (r < 0) break;
    if (r > 0) not_fresh++;
    /* The model: ports as connected in 4C's connect dialog. */
    pos = ccomm4c_get(CCOMM4C_IN_POSITION);
    vel = ccomm4c_get(CCOMM4C_IN_VELOCITY);
    ok = ccomm4c_get(CCOMM4C_IN_CCOMM_OK);
    error = reference - pos;
    ccomm4c_set(CCOMM4C_OUT_SETPOINT, ok * (kp * error - kd * vel));
    integral += h * error;
    ccomm4c_set(CCOMM4C_OUT_ERROR_INTEGRAL, integral);
    if (ccomm4c_output() < 0) break;
    cycles++;
    next += (int64_t)(h * 1e9);
    while (ccomm_sleep_until(next) != 0 && !stop) {
    }
  }
  ccomm4c_terminate();
  printf("harness_4c: cycles=%lu periods_with_stale_inputs=%lu\n", cycles, not_fresh);
  return r < 0 ? 3 : 0;
}
