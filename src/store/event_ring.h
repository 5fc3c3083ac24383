// SPDX-License-Identifier: Apache-2.0
// Event signals: a bounded broadcast ring. Every reader (each client handle, and
// ccommd for forwarded signals) has its own cursor and sees every event, or learns
// exactly how many it lost. Nothing is dropped silently.
//
// A writer claims ticket h by CAS on `head`, then slot h % depth by CAS-ing its seq
// from the previous (even) value to 2h+1, copies, and stores 2h+2. A reader at cursor
// c accepts slot c % depth only if seq == 2c+2 before and after the copy.
//
// Invariants:
//   - With backpressure (forwarded signals), head - fwd_cursor never exceeds depth:
//     the writer gets kFull and the event is refused, not lost. Without it, the ring
//     overwrites the oldest event and a lagging reader counts the overrun.
//   - A writer killed (or stalled for a whole lap) between claiming a ticket and
//     completing it leaves a hole: readers wait for it at most kHoleTimeoutNs, then
//     skip it and count it lost. No reader stalls forever.
//   - A reader polling an empty ring touches only the next slot's line (and `head`
//     every kHeadRecheckNs), so writers keep `head` in their cache. Hence kEmpty means
//     "nothing new as of at most kHeadRecheckNs ago" behind a hole, never longer.
//   - Every loop is bounded.
#pragma once

#include <atomic>
#include <cstdint>

#include "common/platform.h"
#include "store/layout.h"
#include "store/state_slot.h"
#include "store/word_copy.h"

namespace ccomm {
namespace store {

constexpr uint64_t kHoleTimeoutNs = 50ull * 1000 * 1000;

struct RingView {
  EventRing* ring = nullptr;
  uint8_t* slots = nullptr;  // depth * slot_bytes
  uint32_t slot_bytes = 0;
  uint32_t value_bytes = 0;
  uint32_t depth = 0;         // power of two
  bool backpressure = false;  // refuse writes when ccommd's cursor is a full ring behind

  SlotHeader* slot(uint64_t ticket) const {
    return reinterpret_cast<SlotHeader*>(slots + (ticket & (depth - 1)) * slot_bytes);
  }
};

/// Appends an event. Returns kOk, kFull (backpressure) or kBusy (the slot's previous
/// occupant is still being written: its writer stalled a full lap or died).
inline StoreResult RingWrite(const RingView& v, const void* value, uint64_t value_seq,
                             uint64_t source_time_ns, uint64_t local_time_ns,
                             uint64_t* seq_out = nullptr) {
  uint64_t h = v.ring->head.load(std::memory_order_acquire);
  for (int attempt = 0;; ++attempt) {
    if (attempt == 64) return StoreResult::kBusy;
    if (v.backpressure && h - v.ring->fwd_cursor.load(std::memory_order_acquire) >= v.depth)
      return StoreResult::kFull;
    if (v.ring->head.compare_exchange_weak(h, h + 1, std::memory_order_acq_rel,
                                           std::memory_order_acquire))
      break;
  }
  SlotHeader* s = v.slot(h);
  if (!ClaimCopy(s, h)) return StoreResult::kBusy;  // ticket h stays a hole; readers skip it after a timeout
  const SlotMeta meta{value_seq ? value_seq : h + 1, source_time_ns, local_time_ns};
  PublishSlot(s, h, v.value_bytes, value, meta);
  v.ring->published.fetch_add(1, std::memory_order_seq_cst);  // ccomm_wait's change counter (rx_waiters)
  if (seq_out) *seq_out = meta.value_seq;
  return StoreResult::kOk;
}

/// Change counter for ccomm_wait(): seq_cst, ordered with SegmentHeader::rx_waiters.
inline uint64_t RingChangeCount(const RingView& v) { return v.ring->published.load(std::memory_order_seq_cst); }

/// ccommd's forwarding position (writers' backpressure is measured against it).
inline uint64_t RingForwardCursor(const RingView& v) { return v.ring->fwd_cursor.load(std::memory_order_acquire); }
inline void SetRingForwardCursor(const RingView& v, uint64_t next) {
  v.ring->fwd_cursor.store(next, std::memory_order_release);
}

/// A reader's position in one ring.
struct RingCursor {
  uint64_t next = 0;         // next ticket to read
  uint64_t stuck_since = 0;  // when `next` was first seen incomplete (0 = not stuck)
  uint64_t lost = 0;         // events this reader lost (overrun or skipped holes)
  uint64_t known_head = 0;   // `head` at the last look (RingRead)
  uint64_t head_seen_ns = 0; // when that look was
};

/// How long a reader that has caught up trusts its last look at `head` (RingRead).
constexpr uint64_t kHeadRecheckNs = 100ull * 1000;

/// Starts a cursor at the ring's current head (only events from now on).
inline void RingSubscribe(const RingView& v, RingCursor* c) {
  c->next = v.ring->head.load(std::memory_order_acquire);
  c->known_head = c->next;
  c->head_seen_ns = 0;
  c->stuck_since = 0;
}

/// Pops the next event for this cursor: kOk, kEmpty, kPending (the next event is
/// claimed but not complete; try again) or kCorrupt (the next event failed its check:
/// skipped and counted lost for this cursor). `now_ns` times out holes and spaces out the
/// reader's looks at `head`; 0 = look every time.
inline StoreResult RingRead(const RingView& v, RingCursor* c, void* out, SlotMeta* meta,
                            uint64_t now_ns) {
  for (int attempt = 0; attempt < 8; ++attempt) {
    uint64_t t = c->next;
    const SlotHeader* s = v.slot(t);
    uint64_t s1 = s->seq.load(std::memory_order_acquire);
    if (s1 == 2 * t + 2) {
      const CopyResult r = ReadSlot(s, t, v.value_bytes, out, meta);
      if (r != CopyResult::kChanged) {
        c->next = t + 1;
        c->stuck_since = 0;
        if (r == CopyResult::kOk) return StoreResult::kOk;
        c->lost++;  // a damaged event is skipped (and counted by the caller), never returned
        return StoreResult::kCorrupt;
      }
      continue;  // overwritten while copying: we were lapped; recheck below
    }
    // Slot not yet claimed for ticket t and the reader has caught up with `head` as
    // last seen: nothing new. Only `head` can tell a hole (a writer that died between
    // its two claims) from an empty ring, but reading it on every poll would pull the
    // writers' line to a spinning reader; it is looked at again after kHeadRecheckNs.
    if (s1 < 2 * t + 1 && t >= c->known_head && now_ns && now_ns - c->head_seen_ns < kHeadRecheckNs)
      return StoreResult::kEmpty;
    uint64_t head = v.ring->head.load(std::memory_order_acquire);
    c->known_head = head;
    c->head_seen_ns = now_ns;
    if (head <= t) return StoreResult::kEmpty;
    if (s1 > 2 * t + 2 || head - t > v.depth) {
      // Lapped: the oldest event still in the ring is head - depth.
      uint64_t oldest = head > v.depth ? head - v.depth : 0;
      if (oldest <= t) oldest = t + 1;
      c->lost += oldest - t;
      c->next = oldest;
      c->stuck_since = 0;
      continue;
    }
    // Ticket t is claimed but not complete.
    if (c->stuck_since == 0) {
      c->stuck_since = now_ns ? now_ns : 1;
      return StoreResult::kPending;
    }
    if (now_ns - c->stuck_since < kHoleTimeoutNs) return StoreResult::kPending;
    c->lost += 1;  // its writer died or stalled: skip the hole
    c->next = t + 1;
    c->stuck_since = 0;
  }
  return StoreResult::kPending;
}

}  // namespace store
}  // namespace ccomm
