// SPDX-License-Identifier: Apache-2.0
// The applications' OS calls on Windows (app_os.h): a high-resolution waitable timer for
// the rest of the period (no absolute timer on the QPC clock), a larger working set in
// place of mlockall, THREAD_PRIORITY_TIME_CRITICAL in place of SCHED_FIFO.
#include <errno.h>

// clang-format off
#include <windows.h>
// clang-format on

#include "ccomm/ccomm.h"
#include "tools/app_os.h"

namespace ccomm {
namespace app {

void SleepUntilNs(int64_t deadline_ns) {
  const int64_t now = ccomm_now();
  if (deadline_ns <= now) return;
  static thread_local HANDLE timer = [] {
    HANDLE t = CreateWaitableTimerExW(nullptr, nullptr, 0x00000002 /*CREATE_WAITABLE_TIMER_HIGH_RESOLUTION*/,
                                      TIMER_ALL_ACCESS);
    return t ? t : CreateWaitableTimerExW(nullptr, nullptr, 0, TIMER_ALL_ACCESS);
  }();
  LARGE_INTEGER due;
  due.QuadPart = -((deadline_ns - now + 99) / 100);  // relative, 100 ns units
  if (timer && SetWaitableTimer(timer, &due, 0, nullptr, nullptr, FALSE)) WaitForSingleObject(timer, INFINITE);
  else Sleep(static_cast<DWORD>((deadline_ns - now) / 1000000));
}

int LockMemory() {
  // The working set the memory manager keeps resident: room for the process's pages.
  return SetProcessWorkingSetSize(GetCurrentProcess(), 64u << 20, 256u << 20) ? 0 : EPERM;
}

int SetFifoPriority(int /*priority*/) {
  return SetThreadPriority(GetCurrentThread(), THREAD_PRIORITY_TIME_CRITICAL) ? 0 : EPERM;
}

int PinToCpu(int cpu) {
  if (cpu < 0 || cpu >= static_cast<int>(8 * sizeof(DWORD_PTR))) return EINVAL;  // one processor group's mask
  return SetThreadAffinityMask(GetCurrentThread(), DWORD_PTR{1} << cpu) ? 0 : EINVAL;
}

}  // namespace app
}  // namespace ccomm
