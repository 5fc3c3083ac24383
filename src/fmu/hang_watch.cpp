// SPDX-License-Identifier: Apache-2.0
#include "hang_watch.h"

#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "fmu_binary.h"

namespace ccomm::fmu {
namespace {

// Read by the signal handler only (set once before the timer starts).
char g_model[128] = "";
volatile uint64_t* g_cycles = nullptr;
volatile sig_atomic_t* g_stop = nullptr;
int64_t g_tick_ns = 0;
uint64_t g_last_cycle = 0;
int g_quiet_ticks = 0;

void Put(const char* s) { (void)!write(2, s, std::strlen(s)); }
void PutUint(uint64_t v) {
  char num[24];
  int i = sizeof num - 1;
  num[i] = '\0';
  do { num[--i] = static_cast<char>('0' + v % 10); v /= 10; } while (v != 0 && i > 0);
  Put(num + i);
}
bool InDoStep(const char* call) {  // g_current_call points at "fmi3DoStep" or "fmi2DoStep" then
  return call != nullptr && std::strncmp(call, "fmi", 3) == 0 && std::strcmp(call + 4, "DoStep") == 0;
}

void OnTick(int) {
  const int saved_errno = errno;
  const uint64_t cycle = *g_cycles;
  if (!InDoStep(g_current_call) || cycle != g_last_cycle) {
    g_last_cycle = cycle;
    g_quiet_ticks = 0;
    errno = saved_errno;
    return;
  }
  ++g_quiet_ticks;
  if (g_quiet_ticks < 4 && !(*g_stop && g_quiet_ticks >= 1)) {
    errno = saved_errno;
    return;
  }
  Put("ccomm-fmu: the FMU ");
  Put(g_model);
  Put(" has not returned from ");
  Put(g_current_call);
  Put(" for ");
  PutUint(static_cast<uint64_t>(g_quiet_ticks * g_tick_ns / 1000000));
  Put(" ms or more (cycle ");
  PutUint(cycle);
  Put(*g_stop ? "; asked to stop): it hangs" : "): it hangs (--hang-timeout)");
  Put("; the task stops, its outputs turn stale for their consumers\n");
  _exit(3);
}

}  // namespace

bool StartHangWatch(int64_t timeout_ns, const char* model_name, volatile uint64_t* cycles,
                    volatile sig_atomic_t* stop, std::string* error) {
  std::snprintf(g_model, sizeof g_model, "%s", model_name);
  g_cycles = cycles;
  g_stop = stop;
  g_tick_ns = timeout_ns / 4;
  struct sigaction sa {};
  sa.sa_handler = OnTick;
  sa.sa_flags = SA_RESTART;  // the FMU's own system calls go on across a tick
  sigaction(SIGALRM, &sa, nullptr);
  sigevent ev{};
  ev.sigev_notify = SIGEV_SIGNAL;
  ev.sigev_signo = SIGALRM;
  timer_t timer;
  if (timer_create(CLOCK_MONOTONIC, &ev, &timer) != 0) {
    *error = std::string("cannot create the hang watch's timer: ") + std::strerror(errno);
    return false;
  }
  itimerspec spec{};
  spec.it_interval.tv_sec = g_tick_ns / 1000000000;
  spec.it_interval.tv_nsec = g_tick_ns % 1000000000;
  spec.it_value = spec.it_interval;
  if (timer_settime(timer, 0, &spec, nullptr) != 0) {
    *error = std::string("cannot start the hang watch's timer: ") + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace ccomm::fmu
