// SPDX-License-Identifier: Apache-2.0
// The POSIX unit of common/public/platform_app.h's clock, sleeps and real-time set-up (Linux,
// glibc; Xenomai's POSIX skin wraps these calls in ccommd).
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#include "common/public/platform_app.h"

namespace ccomm {
namespace platform {

uint64_t MonotonicNs() {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
}

namespace {
struct timespec Timespec(uint64_t ns) {
  return {static_cast<time_t>(ns / 1000000000ull), static_cast<long>(ns % 1000000000ull)};
}
}  // namespace

void SleepNs(uint64_t ns) {
  struct timespec ts = Timespec(ns);
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

int SleepNsInterruptible(uint64_t ns) {
  const struct timespec ts = Timespec(ns);
  return nanosleep(&ts, nullptr) == 0 ? 0 : -errno;
}

int SleepUntilNs(int64_t deadline_ns) {
  const struct timespec ts = {static_cast<time_t>(deadline_ns / 1000000000), static_cast<long>(deadline_ns % 1000000000)};
  return -clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);  // returns the error, not -1
}

RealtimeResult SetUpRealtime(const RealtimeRequest& request) {
  RealtimeResult result;
  if (request.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(request.cpu, &set);
    result.cpu = -pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  }
  if (request.lock_memory) result.lock_memory = mlockall(MCL_CURRENT | MCL_FUTURE) == 0 ? 0 : -errno;
  if (request.fifo_priority > 0) {
    struct sched_param sp;
    memset(&sp, 0, sizeof sp);
    sp.sched_priority = request.fifo_priority;
    result.fifo_priority = -pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  }
  return result;
}

uint64_t ProcessCpuNs() {
  struct timespec ts;
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
}

}  // namespace platform
}  // namespace ccomm
