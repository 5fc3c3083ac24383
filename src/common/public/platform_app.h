// SPDX-License-Identifier: Apache-2.0
// The part of the platform layer that the programs of the public API (ccomm, ccomm-latency,
// ccomm-fmu, ccomm-ros2) use besides ccomm.h: the clock, sleeping, the one real-time
// set-up, an exclusive lock (and the group its object gets) and the names of a node's shared-memory objects. ccommd and
// the library use the same functions: common/platform.h includes this header.
// It includes standard headers only, so that a program including it pulls in nothing of
// the core (tests/structure/check_layering.py, PUBLIC_INTERFACES), and its units are the
// library ccomm_platform_app (src/common/CMakeLists.txt), one whole file per platform:
//   platform/posix/realtime.cpp, platform/posix/exclusive_lock.cpp
//   platform/windows/realtime.cpp, platform/windows/exclusive_lock.cpp
#pragma once

#include <cstdint>
#include <cstdlib>
#include <string>

namespace ccomm {
namespace platform {

/// [rt] CLOCK_MONOTONIC in ns (vDSO, no syscall on Linux; QueryPerformanceCounter on
/// Windows): ccomm_now()'s clock.
uint64_t MonotonicNs();

/// Sleeps `ns` nanoseconds, on through signals (not [rt]: a syscall; for idle and back-off waits).
void SleepNs(uint64_t ns);
/// Sleeps `ns` nanoseconds unless a signal handler runs first (a watch loop's Ctrl-C):
/// 0, or -EINTR when a signal ended it early (never on Windows).
int SleepNsInterruptible(uint64_t ns);
/// Sleeps until MonotonicNs() reaches `deadline_ns` (absolute: a periodic loop keeps its
/// period). 0, or -EINTR when a signal handler ended it early (the caller decides whether
/// to sleep on), or another -errno.
int SleepUntilNs(int64_t deadline_ns);

/// What a program asks of SetUpRealtime; every part is optional.
struct RealtimeRequest {
  int cpu = -1;              ///< >= 0: pin the calling thread to this CPU
  bool lock_memory = false;  ///< lock the process's current and future memory
  int fifo_priority = 0;     ///< > 0: SCHED_FIFO with this priority (1..99) for the calling thread
};
/// What each part gave: 0, or -errno. A part not asked for is 0.
struct RealtimeResult {
  int cpu = 0;
  int lock_memory = 0;
  int fifo_priority = 0;
};
/// The real-time set-up of ccommd's threads, ccomm-fmu, ccomm-ros2 and ccomm-latency, in
/// this order: the CPU (pages the memory lock faults in are then touched where the loop
/// runs), the memory lock, the priority (the set-up itself does not run at real-time
/// priority). POSIX: pthread_setaffinity_np, mlockall(MCL_CURRENT | MCL_FUTURE),
/// pthread_setschedparam(SCHED_FIFO); Windows: SetThreadAffinityMask, a larger working set,
/// THREAD_PRIORITY_TIME_CRITICAL. The caller says what failed, in its own words. Not [rt].
RealtimeResult SetUpRealtime(const RealtimeRequest& request);

/// CPU time this process has used so far, every thread, user and system, in ns
/// (CLOCK_PROCESS_CPUTIME_ID; Windows: GetProcessTimes). For a benchmark's own account of
/// its measured window (ccomm-latency's cpu_ns). Not [rt]: a system call.
uint64_t ProcessCpuNs();

/// An exclusive lock on the object `name` (an shm name) that this process holds until it
/// exits or dies, also while it is stopped (a SIGSTOPped ccommd keeps its node). Returns a
/// handle to keep (>= 0), -EBUSY (the holder's pid in *holder_pid when known, else 0), or
/// -errno. `gid` >= 0 gives the object to that group.
int LockExclusive(const char* name, int gid, int* holder_pid);
/// Gives up a lock LockExclusive returned.
void UnlockExclusive(int handle);
/// The id of group `name` (getgrnam), or -1 if there is none (always on Windows, where a
/// segment's access follows the mapping's namespace, docs/install.md): the `gid` of the
/// shared objects ccommd and ccomm-ros2 make. Start-up only.
int NamedGroupId(const char* name);

/// The shm name of node `node`'s segment: $CCOMM_SHM_PREFIX (default "/ccomm.") + node.
/// The node's other objects are named by a suffix to it (".view", ".lock",
/// ".ros2-domain<N>"). The one place the name is built.
inline std::string SegmentName(const std::string& node) {
  const char* prefix = std::getenv("CCOMM_SHM_PREFIX");
  return std::string(prefix && *prefix ? prefix : "/ccomm.") + node;
}

}  // namespace platform
}  // namespace ccomm
