// SPDX-License-Identifier: Apache-2.0
// State signals: the last value wins, many writers and many readers, lock-free.
//
// A StateCell owns kStateSlots copies. A writer takes a ticket t (fetch_add), claims
// slot t % kStateSlots by CAS-ing its seq from an even value to 2t+1, copies the value,
// stores seq = 2t+2 and raises `latest` to t+1. A reader copies slot (latest-1) and
// accepts it only if seq == 2(latest-1)+2 before and after the copy (seqlock).
//
// Small values (<= kInlineValueBytes) are also copied into the cell's first line
// (`inline_seq`, a seqlock whose writer is chosen by `inline_claim` on the writers'
// line, claimed for the same ticket after the slot is complete and held until `latest`
// is published),
// and a reader takes that copy when it is complete and not older than `latest` (it may
// be the next value, whose writer has not published yet): the reader then touches one
// cache line, and sees a new value as soon as the copy's stores land. The slot stays the durable copy: when the inline copy is being rewritten,
// or its writer died, readers fall back to the slot.
//
// Invariants:
//   - The slot holding `latest` is never claimed: a newer complete copy must exist
//     before the newest one can be overwritten, so readers always find a valid copy.
//   - A writer killed mid-copy leaves its slot odd; later writers skip odd slots,
//     readers never look at it (it never became `latest`). Nothing stalls, and ccommd
//     gives the slot back once it sees the writer is dead (reclaim.h).
//   - Every loop is bounded; under absurd contention the call reports kBusy instead
//     of spinning.
#pragma once

#include <atomic>
#include <cstdint>

#include "common/platform.h"
#include "store/layout.h"
#include "store/seqlock.h"

namespace ccomm {
namespace store {

struct StateView {
  StateCell* cell = nullptr;
  uint8_t* slots = nullptr;  // kStateSlots * slot_bytes
  uint32_t slot_bytes = 0;
  uint32_t value_bytes = 0;

  SlotHeader* slot(uint64_t ticket) const {
    return reinterpret_cast<SlotHeader*>(slots + (ticket % kStateSlots) * slot_bytes);
  }
};

/// kCorrupt: the copy a read found failed its check (a client wrote over shared memory);
/// nothing was returned.
enum class StoreResult { kOk, kNever, kEmpty, kPending, kBusy, kFull, kCorrupt };

/// Claims the cell's inline copy for ticket t, unless a newer ticket holds it or
/// another writer is filling it (then readers use the slot: nothing is lost). The
/// claim lives on line 1; the holder fills line 0 with plain stores (FillInline),
/// publishes `latest` and only then releases the claim (ReleaseInline), so the inline
/// copy is never older than `latest - 1` while it is complete (see StateRead).
inline bool ClaimInline(const StateView& v, uint64_t t) { return ClaimCopy(&v.cell->inline_claim, t); }

/// Fills the inline copy (the caller holds the inline claim for ticket t).
inline void FillInline(const StateView& v, uint64_t t, const SlotMeta& meta, const void* value) {
  StateCell* c = v.cell;
  c->inline_seq.store(2 * t + 1, std::memory_order_release);  // after `latest` passed the last copy (StateReadCopies)
  StampAndPublish(&c->inline_seq, c->inline_meta, reinterpret_cast<uint8_t*>(c->inline_value), t, v.value_bytes,
                  value, meta);
}

inline void ReleaseInline(const StateView& v, uint64_t t) {
  v.cell->inline_claim.seq.store(2 * t + 2, std::memory_order_release);
}

/// Raises `latest` to t+1 unless a newer copy is already published. Each failed CAS
/// means another writer published, so this ends within #writers tries. seq_cst: see
/// SegmentHeader::rx_waiters.
inline void PublishLatest(const StateView& v, uint64_t t) {
  uint64_t cur = v.cell->latest.load(std::memory_order_relaxed);
  while (cur < t + 1 &&
         !v.cell->latest.compare_exchange_weak(cur, t + 1, std::memory_order_seq_cst, std::memory_order_relaxed)) {
  }
}

/// Writes a value. value_seq == 0 means "number it": the ticket + 1 is used.
/// Returns kOk or kBusy. On kOk, *seq_out (if given) is the value's sequence number.
inline StoreResult StateWrite(const StateView& v, const void* value, uint64_t value_seq,
                              uint64_t source_time_ns, uint64_t local_time_ns,
                              uint64_t* seq_out = nullptr) {
  for (uint32_t attempt = 0; attempt < 2 * kStateSlots; ++attempt) {
    uint64_t t = v.cell->next_ticket.fetch_add(1, std::memory_order_relaxed);
    uint64_t latest = v.cell->latest.load(std::memory_order_acquire);
    if (latest != 0 && (latest - 1) % kStateSlots == t % kStateSlots) continue;  // newest copy
    SlotHeader* h = v.slot(t);
    if (!ClaimCopy(h, t)) continue;  // being written (or its writer died), or newer
    const SlotMeta meta{value_seq ? value_seq : t + 1, source_time_ns, local_time_ns};
    PublishSlot(h, t, v.value_bytes, value, meta);
    const bool inl = v.value_bytes <= kInlineValueBytes && ClaimInline(v, t);
    if (inl) FillInline(v, t, meta, value);
    PublishLatest(v, t);
    if (inl) ReleaseInline(v, t);
    if (seq_out) *seq_out = meta.value_seq;
    return StoreResult::kOk;
  }
  return StoreResult::kBusy;
}

/// Single-writer store, for a state that one thread of one process writes and nobody
/// else: a signal received from another node, written only by ccommd's receive thread
/// (clients may not write it: ccomm_write refuses what is not produced here). Plain
/// release stores instead of a ticket, claims and CAS; readers see the same copies as
/// from StateWrite (StateRead is unchanged). Ticket t = `latest`: the writer's own last
/// publish, so its slot is never the one holding `latest`. Crash safety: a ccommd killed
/// mid-copy leaves that copy odd (readers skip it, or fall back from the inline copy to
/// the slot of `latest`); the restarted ccommd adopts the segment and rewrites ticket
/// `latest` from scratch. A reclaim scan that zeroes a copy being written only makes it
/// look incomplete until its publish. The check is computed once for both copies.
/// `latest` is stored with release order; the caller must call PublishedStoresFence()
/// before it looks at SegmentHeader::rx_waiters (once per frame, not per value).
__attribute__((always_inline)) inline void StateWriteSingleCopies(const StateView& v, const void* value,
                                                                  const SlotMeta& meta, uint32_t value_bytes) {
  StateCell* c = v.cell;
  const uint64_t t = c->latest.load(std::memory_order_relaxed);
  const uint64_t check = CopyCheck(meta, value, value_bytes);
  SlotHeader* h = v.slot(t);
  h->seq.store(2 * t + 1, std::memory_order_relaxed);
  StampCheckedAndPublish(&h->seq, &h->value_seq, reinterpret_cast<uint8_t*>(h + 1), t, value_bytes, value, meta,
                         check);
  if (value_bytes <= kInlineValueBytes) {
    c->inline_seq.store(2 * t + 1, std::memory_order_release);  // after `latest` passed the last copy (StateReadCopies)
    StampCheckedAndPublish(&c->inline_seq, c->inline_meta, reinterpret_cast<uint8_t*>(c->inline_value), t,
                           value_bytes, value, meta, check);
  }
#ifdef CCOMM_TSAN
  c->latest.store(t + 1, std::memory_order_seq_cst);  // TSan does not model the fence below
#else
  c->latest.store(t + 1, std::memory_order_release);
#endif
}
__attribute__((always_inline)) inline void StateWriteSingle(const StateView& v, const void* value,
                                                           const SlotMeta& meta) {
  if (v.value_bytes == 8) StateWriteSingleCopies(v, value, meta, 8);  // constant size: no loops, no branches
  else StateWriteSingleCopies(v, value, meta, v.value_bytes);
}

/// Orders every StateWriteSingle before the caller's following load of rx_waiters (the
/// Dekker pair of SegmentHeader::rx_waiters): one full fence per frame.
inline void PublishedStoresFence() {
#ifndef CCOMM_TSAN
  std::atomic_thread_fence(std::memory_order_seq_cst);
#endif
}

/// Copies the newest complete value. Returns kOk, kNever (nothing written yet), kBusy
/// (writers overtook the reader 16 times in a row) or kCorrupt (see seqlock.h).
__attribute__((always_inline)) inline StoreResult StateReadCopies(const StateView& v, void* out, SlotMeta* meta,
                                                                   uint32_t value_bytes) {
  for (int attempt = 0; attempt < 16; ++attempt) {
    uint64_t latest = v.cell->latest.load(std::memory_order_acquire);
    if (latest == 0) return StoreResult::kNever;
    uint64_t t = latest - 1;
    if (value_bytes <= kInlineValueBytes) {
      // The inline copy, if complete and not older than `latest`: it may be newer (its
      // writer has not published yet).
      uint64_t s1 = v.cell->inline_seq.load(std::memory_order_acquire);
      if (!(s1 & 1) && s1 >= 2 * t + 2) {
        uint64_t ti = s1 / 2 - 1;
        const CopyResult r = ReadCopy(&v.cell->inline_seq, v.cell->inline_meta,
                                      reinterpret_cast<const uint8_t*>(v.cell->inline_value), ti, value_bytes, out,
                                      meta);
        if (r == CopyResult::kOk) return StoreResult::kOk;
        if (r == CopyResult::kCorrupt) return StoreResult::kCorrupt;
        continue;  // refilled while we copied
      }
      // Not usable (being rewritten, or older than `latest`): the slot of `latest`, loaded
      // again after s1. A copy is rewritten only after its last value's writer raised
      // `latest` past it (and the rewrite's first store is a release), so the reloaded
      // `latest` is never older than a copy this reader returned before. The `latest` of
      // the first load can be: loaded, then the writer publishes and starts the next
      // copy, and its slot would hand the reader an older value than its last read.
      latest = v.cell->latest.load(std::memory_order_acquire);
      t = latest - 1;
    }
    const CopyResult r = ReadSlot(v.slot(t), t, value_bytes, out, meta);
    if (r == CopyResult::kOk) return StoreResult::kOk;
    if (r == CopyResult::kCorrupt) return StoreResult::kCorrupt;
  }
  return StoreResult::kBusy;
}

/// The value_bytes == 8 case (one double or int64) compiled with the size known.
__attribute__((always_inline)) inline StoreResult StateRead(const StateView& v, void* out, SlotMeta* meta) {
  if (v.value_bytes == 8) return StateReadCopies(v, out, meta, 8);
  return StateReadCopies(v, out, meta, v.value_bytes);
}

/// Copies the value of ticket t if its slot still holds it, complete: a state keeps its
/// last kStateSlots copies, so the sender can still forward values a writer replaced
/// before ccommd took them (values numbered by the store are ticket + 1). kOk, kEmpty
/// (overwritten, being rewritten, or never written), or kCorrupt (its check failed).
inline StoreResult StateReadTicket(const StateView& v, uint64_t t, void* out, SlotMeta* meta) {
  const CopyResult r = ReadSlot(v.slot(t), t, v.value_bytes, out, meta);
  if (r == CopyResult::kOk) return StoreResult::kOk;
  return r == CopyResult::kCorrupt ? StoreResult::kCorrupt : StoreResult::kEmpty;
}

/// `latest` counter: changes whenever a new value is published (cheap change check).
inline uint64_t StateVersion(const StateView& v) {
  return v.cell->latest.load(std::memory_order_acquire);
}

/// What a reader's cached copy of a state was taken at: `latest` and, for small values,
/// the inline copy's sequence word (it can move ahead of `latest`, see StateRead). Both
/// unchanged means the cached copy is still the newest value.
struct StateStamp {
  uint64_t version = 0;
  uint64_t inline_seq = 0;
  bool operator==(const StateStamp& o) const { return version == o.version && inline_seq == o.inline_seq; }
};
inline StateStamp StateStampOf(const StateView& v, uint32_t value_bytes) {
  StateStamp s;
  s.version = v.cell->latest.load(std::memory_order_acquire);
  s.inline_seq = value_bytes <= kInlineValueBytes ? v.cell->inline_seq.load(std::memory_order_acquire) : 0;
  return s;
}
inline StateStamp StateStampOf(const StateView& v) { return StateStampOf(v, v.value_bytes); }

/// The inline copy's read for a reader that took `s` = StateStampOf(v) just before (a
/// cached reader comparing it with its last copy's): the stamp's inline sequence word is
/// the copy's first look, so a new small value costs no second load of either word.
/// kChanged: that copy is not usable (being rewritten, older than `latest`, a large
/// value, or it moved): StateRead then.
__attribute__((always_inline)) inline CopyResult StateReadInlineStamped(const StateView& v, const StateStamp& s,
                                                                        void* out, SlotMeta* meta,
                                                                        uint32_t value_bytes) {
  // Same test as StateReadCopies (t = version - 1: complete, not older than `latest`).
  if (value_bytes > kInlineValueBytes || s.version == 0 || (s.inline_seq & 1) || s.inline_seq < 2 * s.version)
    return CopyResult::kChanged;
  return ReadCopyAt(&v.cell->inline_seq, s.inline_seq, v.cell->inline_meta,
                    reinterpret_cast<const uint8_t*>(v.cell->inline_value), value_bytes, out, meta);
}

/// StateRead after StateStampOf (see StateReadInlineStamped).
__attribute__((always_inline)) inline StoreResult StateReadStamped(const StateView& v, const StateStamp& s,
                                                                   void* out, SlotMeta* meta, uint32_t value_bytes) {
  const CopyResult r = StateReadInlineStamped(v, s, out, meta, value_bytes);
  if (r == CopyResult::kOk) return StoreResult::kOk;
  if (r == CopyResult::kCorrupt) return StoreResult::kCorrupt;
  return StateReadCopies(v, out, meta, value_bytes);
}

/// Change counter for ccomm_wait(): seq_cst, ordered with SegmentHeader::rx_waiters.
inline uint64_t StateChangeCount(const StateView& v) { return v.cell->latest.load(std::memory_order_seq_cst); }

/// ccommd's forwarding mark: the `latest` it last sent (the cell's forwarder line).
inline uint64_t StateForwarded(const StateView& v) { return v.cell->forwarded.load(std::memory_order_relaxed); }
inline void MarkStateForwarded(const StateView& v, uint64_t version) {
  v.cell->forwarded.store(version, std::memory_order_relaxed);
}

}  // namespace store
}  // namespace ccomm
