// SPDX-License-Identifier: Apache-2.0
// systemd readiness and watchdog; compiles to nothing without libsystemd.
#pragma once

#include <cstdint>

#ifdef CCOMM_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace ccomm {
namespace sd {

inline void NotifyReady() {
#ifdef CCOMM_HAVE_SYSTEMD
  sd_notify(0, "READY=1\nSTATUS=forwarding");
#endif
}
inline void NotifyStopping() {
#ifdef CCOMM_HAVE_SYSTEMD
  sd_notify(0, "STOPPING=1");
#endif
}
inline void NotifyWatchdog() {
#ifdef CCOMM_HAVE_SYSTEMD
  sd_notify(0, "WATCHDOG=1");
#endif
}
/// Watchdog interval asked for by the unit (WatchdogSec=), 0 if none.
inline uint64_t WatchdogIntervalNs() {
#ifdef CCOMM_HAVE_SYSTEMD
  uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) return usec * 1000;
#endif
  return 0;
}

}  // namespace sd
}  // namespace ccomm
