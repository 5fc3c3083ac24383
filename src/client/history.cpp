// SPDX-License-Identifier: Apache-2.0
// The history tap's reader (ccomm.h, ccomm_history_*): a caller-owned cursor over a
// received state's history ring, which ccommd appends to (store/event_ring.h). The
// cursor is the ring's RingCursor spelled in public fields, so the store's overrun and
// hole rules hold unchanged.
#include <string.h>

#include "ccomm/ccomm.h"
#include "client/client_internal.h"
#include "common/platform.h"

namespace st = ccomm::store;

namespace {

bool ValidSignal(const ccomm_client* c, ccomm_signal s) {
  return c && s >= 0 && static_cast<uint32_t>(s) < ccomm::client::SegmentOf(c).signal_count();
}

st::RingCursor FromPublic(const ccomm_history_cursor& p) {
  st::RingCursor r;
  r.next = p.next;
  r.lost = p.overrun;
  r.stuck_since = p.internal[0];
  r.known_head = p.internal[1];
  r.head_seen_ns = p.internal[2];
  return r;
}

void ToPublic(const st::RingCursor& r, ccomm_history_cursor* p) {
  p->next = r.next;
  p->overrun = r.lost;
  p->internal[0] = r.stuck_since;
  p->internal[1] = r.known_head;
  p->internal[2] = r.head_seen_ns;
}

}  // namespace

extern "C" {

int ccomm_history_depth(const ccomm_client* c, ccomm_signal s) {
  if (!ValidSignal(c, s)) return CCOMM_E_INVAL;
  return static_cast<int>(ccomm::client::SegmentOf(c).dir(static_cast<uint32_t>(s)).history_depth);
}

int ccomm_history_start(const ccomm_client* c, ccomm_signal s, uint32_t back, ccomm_history_cursor* cur) {
  if (!ValidSignal(c, s) || !cur) return CCOMM_E_INVAL;
  const st::RingView v = ccomm::client::SegmentOf(c).history(static_cast<uint32_t>(s));
  if (!v.ring) return CCOMM_E_NOENT;
  st::RingCursor r;
  st::RingSubscribe(v, &r);
  const uint64_t kept = r.next < v.depth ? r.next : v.depth;  // values written, at most depth
  r.next -= back < kept ? back : kept;
  memset(cur, 0, sizeof *cur);
  ToPublic(r, cur);
  return 0;
}

int ccomm_history_read(ccomm_client* c, ccomm_signal s, ccomm_history_cursor* cur, void* value, size_t len,
                       ccomm_history_info* info) {
  if (!ValidSignal(c, s) || !cur || !value) return CCOMM_E_INVAL;
  const st::Segment& seg = ccomm::client::SegmentOf(c);
  const uint32_t id = static_cast<uint32_t>(s);
  const st::RingView v = seg.history(id);
  if (!v.ring) return CCOMM_E_NOENT;
  if (len != v.value_bytes) return CCOMM_E_TYPE;
  if (seg.header()->state.load(std::memory_order_relaxed) == st::kRetired) return CCOMM_E_RETIRED;
  st::RingCursor r = FromPublic(*cur);
  st::SlotMeta meta;
  const st::StoreResult res = st::RingRead(v, &r, value, &meta, ccomm::platform::MonotonicNs());
  ToPublic(r, cur);
  if (info) {
    memset(info, 0, sizeof *info);
    info->overrun = r.lost;
    info->lost = seg.stats(id).lost.load(std::memory_order_relaxed);
  }
  if (res == st::StoreResult::kCorrupt) {
    seg.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
    return CCOMM_E_CORRUPT;
  }
  if (res != st::StoreResult::kOk) return CCOMM_EMPTY;
  if (info) {
    info->seq = meta.value_seq;
    info->source_time_ns = meta.source_time_ns;
    info->receive_time_ns = meta.local_time_ns;
  }
  return CCOMM_FRESH;
}

}  // extern "C"
