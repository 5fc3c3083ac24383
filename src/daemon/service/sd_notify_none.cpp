// SPDX-License-Identifier: Apache-2.0
// A build without libsystemd: no service manager to notify (see sd_notify.h).
#include "daemon/service/sd_notify.h"

namespace ccomm {
namespace sd {

void NotifyReady() {}
void NotifyReloading() {}
void NotifyReloaded(const char*) {}
void NotifyStopping() {}
void NotifyWatchdog() {}
uint64_t WatchdogIntervalNs() { return 0; }

}  // namespace sd
}  // namespace ccomm
