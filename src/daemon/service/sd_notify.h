// SPDX-License-Identifier: Apache-2.0
// systemd readiness and watchdog, one unit per build: sd_notify_systemd.cpp (libsystemd)
// or sd_notify_none.cpp (no service manager: every call does nothing). CMake picks it.
#pragma once

#include <cstdint>

namespace ccomm {
namespace sd {

void NotifyReady();
/// A reload begins (RELOADING=1 with MONOTONIC_USEC, which systemd >= 253 asks for); it
/// ends with NotifyReloaded.
void NotifyReloading();
/// A reload ended: READY=1 and `status` as the unit's status line (systemctl status).
void NotifyReloaded(const char* status);
void NotifyStopping();
void NotifyWatchdog();
/// Watchdog interval asked for by the unit (WatchdogSec=), 0 if none.
uint64_t WatchdogIntervalNs();

}  // namespace sd
}  // namespace ccomm
