// SPDX-License-Identifier: Apache-2.0
// systemd readiness and watchdog through libsystemd (see sd_notify.h).
#include <systemd/sd-daemon.h>

#include "daemon/sd_notify.h"

namespace ccomm {
namespace sd {

void NotifyReady() { sd_notify(0, "READY=1\nSTATUS=forwarding"); }
void NotifyStopping() { sd_notify(0, "STOPPING=1"); }
void NotifyWatchdog() { sd_notify(0, "WATCHDOG=1"); }
uint64_t WatchdogIntervalNs() {
  uint64_t usec = 0;
  return sd_watchdog_enabled(0, &usec) > 0 ? usec * 1000 : 0;
}

}  // namespace sd
}  // namespace ccomm
