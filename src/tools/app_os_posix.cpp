// SPDX-License-Identifier: Apache-2.0
// The applications' OS calls on POSIX (app_os.h).
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include "tools/app_os.h"

namespace ccomm {
namespace app {

void SleepUntilNs(int64_t deadline_ns) {
  const struct timespec ts = {static_cast<time_t>(deadline_ns / 1000000000), static_cast<long>(deadline_ns % 1000000000)};
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
}

int LockMemory() { return mlockall(MCL_CURRENT | MCL_FUTURE) == 0 ? 0 : errno; }

int SetFifoPriority(int priority) {
  struct sched_param sp = {};
  sp.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
}

int PinToCpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

}  // namespace app
}  // namespace ccomm
