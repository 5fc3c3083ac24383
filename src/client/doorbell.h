// SPDX-License-Identifier: Apache-2.0
// The doorbells of a libccomm handle: how a write tells ccommd's send thread that a
// forwarded signal changed (tx), how it wakes local ccomm_wait() callers (rx), and how
// ccomm_wait() sleeps. ccommd always sleeps and wakes on the futex words of the
// segment header (store/layout.h), so every mechanism ends in those futexes; they
// differ in which thread makes the FUTEX_WAKE. One unit per mechanism, chosen by CMake
// (src/client/CMakeLists.txt), never by #ifdef:
//   doorbell_futex.cpp  plain Linux: the writer calls FUTEX_WAKE itself (a non-blocking
//                       syscall, only when ccommd sleeps or someone waits).
//   doorbell_xddp.cpp   Xenomai 3 (Cobalt): the writer sends a message on an XDDP socket
//                       (a Cobalt call: no switch to secondary mode) and a Linux relay
//                       thread of the same process makes the FUTEX_WAKE. See
//                       docs/design.md "Xenomai".
#pragma once

#include <cstdint>

#include "store/segment.h"

namespace ccomm {
namespace client {

/// A handle's doorbell state; what it holds depends on the mechanism.
struct Doorbell;

/// Sets up the doorbell of a handle attached to `segment` (which must outlive it).
/// Not [rt]: may allocate, open files and start a thread. 0 or -errno.
int DoorbellOpen(const store::Segment& segment, Doorbell** out);
/// Stops and frees what DoorbellOpen made; null is ignored. Not [rt].
void DoorbellClose(Doorbell* d);

/// [rt] Bumps tx_doorbell and wakes ccommd's send thread if it sleeps.
void DoorbellRingTx(Doorbell* d);
/// [rt] Marks forwarded signal `id` dirty, then bumps tx_doorbell, waking ccommd if
/// `wake` (see store::Segment::NotifyTx).
void DoorbellNotifyTx(Doorbell* d, uint32_t id, bool wake);
/// [rt] Wakes ccomm_wait() callers on this node, if any (after a StateWrite/RingWrite).
void DoorbellNotifyRx(Doorbell* d);
/// Sleeps while rx_doorbell == `seen`, at most `timeout_ns` (< 0: no limit); returns
/// early on a wake-up or a signal. Blocking, but under Xenomai it stays in primary mode.
void DoorbellWait(Doorbell* d, uint32_t seen, int64_t timeout_ns);

}  // namespace client
}  // namespace ccomm
