// SPDX-License-Identifier: Apache-2.0
// The floor of ccomm-fmu's jitter: the same periodic task with nothing in it. SCHED_FIFO
// (if permitted), mlockall, one clock reading per cycle, absolute clock_nanosleep; prints
// the wake-up lateness (mean, p99, max) over N cycles.
//   bare_loop PERIOD_NS CYCLES PRIORITY
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <time.h>

static int64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1000000000LL + ts.tv_nsec;
}
static int by_value(const void* a, const void* b) {
  int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
  return (x > y) - (x < y);
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: bare_loop PERIOD_NS CYCLES PRIORITY\n");
    return 2;
  }
  const int64_t period = atoll(argv[1]);
  const long cycles = atol(argv[2]);
  int64_t* late = calloc((size_t)cycles, sizeof *late);
  if (late == NULL || period <= 0 || cycles <= 0) return 2;
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) fprintf(stderr, "bare_loop: mlockall failed\n");
  struct sched_param sp = {.sched_priority = atoi(argv[3])};
  if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) fprintf(stderr, "bare_loop: SCHED_FIFO not permitted\n");
  int64_t release = now_ns(), overruns = 0, sum = 0;
  for (long k = 0; k < cycles; ++k) {
    int64_t l = now_ns() - release;
    if (l >= period) {
      overruns += l / period;
      release += (l / period) * period;
      l %= period;
    }
    late[k] = l;
    sum += l;
    release += period;
    struct timespec ts = {(time_t)(release / 1000000000LL), (long)(release % 1000000000LL)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
  }
  qsort(late, (size_t)cycles, sizeof *late, by_value);
  printf("bare_loop: %ld cycles, %lld overruns, lateness mean %.1f us p99 %.1f us max %.1f us\n", cycles,
         (long long)overruns, sum / 1e3 / cycles, late[cycles * 99 / 100] / 1e3, late[cycles - 1] / 1e3);
  free(late);
  return 0;
}
