// SPDX-License-Identifier: Apache-2.0
// A libccomm handle's definition, private to the units that build it (client_open.cpp)
// and use it on the real-time path (client.cpp). Other units see the handle only
// through client_internal.h.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include "ccomm/ccomm.h"
#include "client/client_internal.h"
#include "client/doorbell.h"
#include "store/segment.h"

// The last copy a handle took of a state signal: while the cell's change words are
// unchanged a read copies from here. A handle polling a signal then reads one or two
// words of the cell per poll: it does not pull the writer's slot lines to its CPU, and
// it holds the readers' line for as short a time as possible while the writer wants it.
struct StateCache {
  ccomm::store::StateStamp stamp;      // the cell's stamp seen before the copy; version 0 = none
  ccomm::store::SlotMeta meta;
  uint8_t* value = nullptr;  // value_bytes; null for event signals
};

// One signal as a handle sees it, resolved at open: a read or write touches this, the
// signal's own lines in the segment and nothing else (no directory or header walks).
struct HandleSignal {
  uint32_t flags = 0;        // SignalFlags
  uint32_t value_bytes = 0;
  uint32_t count = 0;
  uint8_t type = 0;
  uint8_t read8_type = 0;    // `type` if a state of one 8-byte value (ReadState8), else 0
  uint64_t stale_ns = 0;     // 0 = never stale
  ccomm::store::SignalStats* stats = nullptr;
  const uint8_t* safe_value = nullptr;
  ccomm::store::StateView state;       // state signals
  ccomm::store::RingView ring;         // event signals
  ccomm::store::RingCursor cursor;         // event signals: this handle's position
  StateCache cache;
  uint64_t seen = 0;         // change counter at the last ccomm_wait()
  uint8_t* pending = nullptr;   // CCOMM_OPEN_BATCH, state signals produced here: the value
  uint64_t pending_ns = 0;      // written this step and its time, stored at the flush
  bool has_pending = false;
};

struct ccomm_client {
  ccomm::store::Segment segment;
  ccomm::client::Doorbell* doorbell = nullptr;  // tx/rx wake-ups (client/doorbell.h)
  uint32_t flags = 0;
  uint32_t signal_count = 0;
  HandleSignal* sig = nullptr;     // signal_count entries
  uint8_t* cache_bytes = nullptr;  // the caches' values
  uint64_t cycle_ns = 0;           // ccomm_set_time(): "now" for reads and writes; 0 = clock
  bool pending_tx = false;         // CCOMM_OPEN_BATCH: forwarded writes since the last flush
  uint64_t* pending_dirty = nullptr;  // CCOMM_OPEN_BATCH: their dirty bits, handed to ccommd at
                                      // the flush only (signal_count bits)
  uint64_t* pending_states = nullptr; // CCOMM_OPEN_BATCH: state signals with a pending value
  bool pending_rx = false;         // CCOMM_OPEN_BATCH: any write since the last flush
};

namespace ccomm {
namespace client {

/// Compares every signal's change counter with the handle's last look and remembers the
/// new ones: true if anything was written since. O(signals): open and ccomm_wait() only.
bool TakeChanges(ccomm_client* c);

}  // namespace client
}  // namespace ccomm
