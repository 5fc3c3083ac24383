// SPDX-License-Identifier: Apache-2.0
// systemd readiness and watchdog through libsystemd (see sd_notify.h).
#include <systemd/sd-daemon.h>
#include <time.h>

#include "daemon/service/sd_notify.h"

namespace ccomm {
namespace sd {

void NotifyReady() { sd_notify(0, "READY=1\nSTATUS=forwarding"); }
void NotifyReloading() {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  sd_notifyf(0, "RELOADING=1\nMONOTONIC_USEC=%llu",
             static_cast<unsigned long long>(ts.tv_sec) * 1000000ull + static_cast<unsigned long long>(ts.tv_nsec / 1000));
}
void NotifyReloaded(const char* status) { sd_notifyf(0, "READY=1\nSTATUS=%s", status); }
void NotifyStopping() { sd_notify(0, "STOPPING=1"); }
void NotifyWatchdog() { sd_notify(0, "WATCHDOG=1"); }
uint64_t WatchdogIntervalNs() {
  uint64_t usec = 0;
  return sd_watchdog_enabled(0, &usec) > 0 ? usec * 1000 : 0;
}

}  // namespace sd
}  // namespace ccomm
