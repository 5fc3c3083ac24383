// SPDX-License-Identifier: Apache-2.0
// The few OS calls of the applications (ccomm, ccomm-latency) that the public API does not
// offer: cycle timing and real-time settings. The applications use ccomm.h only, not the
// library's platform layer (tests/structure/check_layering.py), so they have this small
// unit of their own, one whole file per platform: app_os_posix.cpp, app_os_windows.cpp.
// Times are ccomm_now()'s clock (CLOCK_MONOTONIC; QueryPerformanceCounter on Windows).
#pragma once

#include <cstdint>

namespace ccomm {
namespace app {

/// Sleeps until ccomm_now() reaches `deadline_ns` (absolute: a periodic loop keeps its
/// period); a signal (Ctrl-C) may end it early.
void SleepUntilNs(int64_t deadline_ns);
/// Locks current and future memory, best effort; 0 or an errno value.
int LockMemory();
/// SCHED_FIFO `priority` for the calling thread (Windows: time-critical); 0 or an errno value.
int SetFifoPriority(int priority);
/// Pins the calling thread to `cpu`; 0 or an errno value.
int PinToCpu(int cpu);

}  // namespace app
}  // namespace ccomm
