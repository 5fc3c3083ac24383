// SPDX-License-Identifier: Apache-2.0
// The Windows unit of common/public/platform_app.h's clock, sleeps and real-time set-up: what
// Windows offers in place of CLOCK_MONOTONIC, nanosleep, mlockall and SCHED_FIFO.
#include <errno.h>

// clang-format off
#include <windows.h>
// clang-format on

#include "common/platform/windows/errno_of.h"
#include "common/public/platform_app.h"

namespace ccomm {
namespace platform {

uint64_t MonotonicNs() {
  static const int64_t freq = [] {
    LARGE_INTEGER f;
    QueryPerformanceFrequency(&f);
    return f.QuadPart;
  }();
  LARGE_INTEGER c;
  QueryPerformanceCounter(&c);  // no kernel call on Windows 10 (TSC page)
  const uint64_t ticks = static_cast<uint64_t>(c.QuadPart), f = static_cast<uint64_t>(freq);
  return ticks / f * 1000000000ull + ticks % f * 1000000000ull / f;
}

void SleepNs(uint64_t ns) {
  // A waitable timer sleeps below Sleep()'s millisecond tick where Windows offers the
  // high-resolution kind (10 1803+); one per thread, made on first use.
  static thread_local HANDLE timer = [] {
    HANDLE t = CreateWaitableTimerExW(nullptr, nullptr, 0x00000002 /*CREATE_WAITABLE_TIMER_HIGH_RESOLUTION*/,
                                      TIMER_ALL_ACCESS);
    return t ? t : CreateWaitableTimerExW(nullptr, nullptr, 0, TIMER_ALL_ACCESS);
  }();
  LARGE_INTEGER due;
  due.QuadPart = -static_cast<LONGLONG>((ns + 99) / 100);  // relative, 100 ns units
  if (timer && SetWaitableTimer(timer, &due, 0, nullptr, nullptr, FALSE)) {
    WaitForSingleObject(timer, INFINITE);
    return;
  }
  Sleep(static_cast<DWORD>((ns + 999999) / 1000000));
}

int SleepNsInterruptible(uint64_t ns) {  // no signal handlers interrupt a wait here
  SleepNs(ns);
  return 0;
}

// No absolute timer on the QPC clock: the rest of the period, relative.
int SleepUntilNs(int64_t deadline_ns) {
  const int64_t now = static_cast<int64_t>(MonotonicNs());
  if (deadline_ns > now) SleepNs(static_cast<uint64_t>(deadline_ns - now));
  return 0;
}

// Pinning: one processor group's mask. Memory: Windows pages a process's memory in and
// out as it likes; a larger working set is the nearest thing to mlockall and needs no
// privilege. Priority: the highest of a normal process's class; the real-time class
// needs the process to ask for it (and administrator rights).
RealtimeResult SetUpRealtime(const RealtimeRequest& request) {
  RealtimeResult result;
  if (request.cpu >= 0)
    result.cpu = request.cpu >= static_cast<int>(8 * sizeof(DWORD_PTR)) ||
                         !SetThreadAffinityMask(GetCurrentThread(), DWORD_PTR{1} << request.cpu)
                     ? -EINVAL
                     : 0;
  if (request.lock_memory && !SetProcessWorkingSetSize(GetCurrentProcess(), 64u << 20, 256u << 20))
    result.lock_memory = -ErrnoOf(GetLastError());
  if (request.fifo_priority > 0 && !SetThreadPriority(GetCurrentThread(), THREAD_PRIORITY_TIME_CRITICAL))
    result.fifo_priority = -EPERM;
  return result;
}

uint64_t ProcessCpuNs() {
  FILETIME created, exited, kernel, user;
  if (!GetProcessTimes(GetCurrentProcess(), &created, &exited, &kernel, &user)) return 0;
  const auto ticks = [](const FILETIME& f) {
    return (static_cast<uint64_t>(f.dwHighDateTime) << 32) | f.dwLowDateTime;  // 100 ns units
  };
  return (ticks(kernel) + ticks(user)) * 100;
}

}  // namespace platform
}  // namespace ccomm
