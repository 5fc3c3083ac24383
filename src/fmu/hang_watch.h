// SPDX-License-Identifier: Apache-2.0
// The hang watch of ccomm-fmu: a doStep that never returns is a failure of the FMU, said
// and ended like any other (exit 3), not a task that spins on silently and ignores SIGTERM.
#pragma once

#include <csignal>
#include <cstdint>
#include <string>

namespace ccomm::fmu {

/// Starts a POSIX timer that ticks every timeout/4 on its own (nothing is added to the
/// cycle). When four ticks in a row find the task inside doStep with no cycle completed,
/// or one tick after a stop was asked, it prints which call hung and for how long and
/// exits with status 3. `cycles` and `stop` are read from the signal handler.
bool StartHangWatch(int64_t timeout_ns, const char* model_name, volatile uint64_t* cycles,
                    volatile sig_atomic_t* stop, std::string* error);

}  // namespace ccomm::fmu
