// SPDX-License-Identifier: Apache-2.0
// Doorbell on plain Linux (see doorbell.h): the writer makes the FUTEX_WAKE itself, only
// when ccommd sleeps (tx_sleeping) or a ccomm_wait() caller waits (rx_waiters); the
// protocol is the store's (store::Segment), used unchanged.
#include <errno.h>

#include <new>

#include "client/doorbell.h"
#include "common/platform.h"

namespace ccomm {
namespace client {

struct Doorbell {
  const store::Segment* segment;
};

int DoorbellOpen(const store::Segment& segment, Doorbell** out) {
  *out = new (std::nothrow) Doorbell{&segment};
  return *out ? 0 : -ENOMEM;
}

void DoorbellClose(Doorbell* d) { delete d; }

void DoorbellRingTx(Doorbell* d) { d->segment->RingTxDoorbell(); }

void DoorbellNotifyTx(Doorbell* d, uint32_t id, bool wake) { d->segment->NotifyTx(id, wake); }

void DoorbellNotifyRx(Doorbell* d) { d->segment->NotifyRx(); }

void DoorbellWait(Doorbell* d, uint32_t seen, int64_t timeout_ns) {
  platform::FutexWait(&d->segment->header()->rx_doorbell, seen, timeout_ns);
}

}  // namespace client
}  // namespace ccomm
