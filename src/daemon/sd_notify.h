// SPDX-License-Identifier: Apache-2.0
// systemd readiness and watchdog, one unit per build: sd_notify_systemd.cpp (libsystemd)
// or sd_notify_none.cpp (no service manager: every call does nothing). CMake picks it.
#pragma once

#include <cstdint>

namespace ccomm {
namespace sd {

void NotifyReady();
void NotifyStopping();
void NotifyWatchdog();
/// Watchdog interval asked for by the unit (WatchdogSec=), 0 if none.
uint64_t WatchdogIntervalNs();

}  // namespace sd
}  // namespace ccomm
