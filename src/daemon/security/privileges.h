// SPDX-License-Identifier: Apache-2.0
// Least privilege: once ccommd has opened its socket (CAP_NET_RAW for raw Ethernet),
// created its segment and locked its memory, it needs no capability any more. Called
// by main() before the I/O threads are created, so they inherit the reduced sets
// (capabilities are per thread on Linux).
#pragma once

#include <string>

#include "config/config.h"

namespace ccomm {

/// Drops every capability (effective, permitted, inheritable, ambient, and the bounding
/// set where allowed) and sets no_new_privs. What the threads still need is moved to
/// resource limits first: SCHED_FIFO `rt.priority` through RLIMIT_RTPRIO, and (with
/// mlockall) future thread stacks through RLIMIT_MEMLOCK = infinity. If a limit cannot
/// be raised (no CAP_SYS_RESOURCE and too low a hard limit), the one capability that
/// stands in for it (CAP_SYS_NICE / CAP_IPC_LOCK) is kept. `realtime` is false with
/// --no-rt. Returns 0 or -errno; `summary` says what was kept, for the log.
int DropPrivileges(const RealtimeConfig& rt, bool realtime, std::string* summary);

}  // namespace ccomm
