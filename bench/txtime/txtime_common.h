// SPDX-License-Identifier: Apache-2.0
// What the two launch-time programs share (txtime_spread.c, txtime_departures.c): a clock
// in nanoseconds and the comparison their percentiles sort with.
#pragma once

#include <stdint.h>
#include <time.h>

static int64_t Ns(clockid_t c) {  /* -1: no such clock here (CLOCK_TAI on an old kernel) */
  struct timespec t;
  return clock_gettime(c, &t) == 0 ? (int64_t)t.tv_sec * 1000000000 + t.tv_nsec : -1;
}
static int Cmp(const void* a, const void* b) {
  int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
  return x < y ? -1 : x > y;
}
