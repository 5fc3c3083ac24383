// SPDX-License-Identifier: Apache-2.0
// The one seqlock sequence of the store: claim, stamp, publish (writer) and copy,
// check (reader). Slots of state cells, slots of event rings and the state cells'
// inline copies all hold a value this way; state_slot.h and event_ring.h decide which
// ticket goes where, this file is how one copy is written and read.
//
// A copy is a sequence word, three meta words (value_seq, source time, local time) and
// the value, padded to 8 bytes. Sequence word for ticket t: 2t+1 while being written,
// 2t+2 when complete. Invariants:
//   - A copy is claimed only from an even sequence word not newer than 2t (a CAS), so
//     two writers never fill one copy and a copy never goes back to an older ticket.
//   - A reader accepts a copy only if the sequence word is 2t+2 before and after
//     taking it; the fences in word_copy.h order the data between the two looks.
#pragma once

#include <atomic>
#include <cstdint>

#include "common/platform.h"
#include "store/layout.h"
#include "store/word_copy.h"

namespace ccomm {
namespace store {

struct SlotMeta {
  uint64_t value_seq = 0;
  uint64_t source_time_ns = 0;
  uint64_t local_time_ns = 0;
};

/// The owner word of a claim: who holds it (reclaim.h gives dead owners' claims back).
inline uint64_t ClaimOwner(uint64_t t) { return (uint64_t{platform::ProcessId()} << 32) | (t & 0xffffffffu); }

/// Claims `slot` for ticket t: false if it is being written, its writer died, it holds
/// a newer ticket, or another writer won the CAS. On true the caller owns the copy
/// until it publishes it.
inline bool ClaimCopy(SlotHeader* slot, uint64_t t) {
  uint64_t s = slot->seq.load(std::memory_order_relaxed);
  if ((s & 1) || s > 2 * t || !slot->seq.compare_exchange_strong(s, 2 * t + 1, std::memory_order_acq_rel))
    return false;
  slot->owner.store(ClaimOwner(t), std::memory_order_relaxed);
  return true;
}

/// Stamps and publishes a claimed copy (its sequence word is 2t+1): meta, value, then
/// the sequence word 2t+2 with release order.
inline void StampAndPublish(std::atomic<uint64_t>* seq, std::atomic<uint64_t>* meta3, uint8_t* data, uint64_t t,
                            uint32_t value_bytes, const void* value, const SlotMeta& meta) {
  SeqlockWriterFence();
  meta3[0].store(meta.value_seq, kMetaStore);
  meta3[1].store(meta.source_time_ns, kMetaStore);
  meta3[2].store(meta.local_time_ns, kMetaStore);
  StoreWords(data, value, value_bytes);
  seq->store(2 * t + 2, std::memory_order_release);
}

/// Copies a seqlocked value if it holds complete ticket t; false if not (yet) or if it
/// changed while being copied.
inline bool ReadCopy(const std::atomic<uint64_t>* seq, const std::atomic<uint64_t>* meta3, const uint8_t* data,
                     uint64_t t, uint32_t value_bytes, void* out, SlotMeta* meta) {
  uint64_t s1 = seq->load(std::memory_order_acquire);
  if (s1 != 2 * t + 2) return false;
  meta->value_seq = meta3[0].load(kMetaLoad);
  meta->source_time_ns = meta3[1].load(kMetaLoad);
  meta->local_time_ns = meta3[2].load(kMetaLoad);
  LoadWords(out, data, value_bytes);
  SeqlockReaderFence();
  return seq->load(std::memory_order_relaxed) == s1;
}

/// A slot's copy (the value follows its header).
inline void PublishSlot(SlotHeader* slot, uint64_t t, uint32_t value_bytes, const void* value, const SlotMeta& meta) {
  StampAndPublish(&slot->seq, &slot->value_seq, reinterpret_cast<uint8_t*>(slot + 1), t, value_bytes, value, meta);
}
inline bool ReadSlot(const SlotHeader* slot, uint64_t t, uint32_t value_bytes, void* out, SlotMeta* meta) {
  return ReadCopy(&slot->seq, &slot->value_seq, reinterpret_cast<const uint8_t*>(slot + 1), t, value_bytes, out, meta);
}

}  // namespace store
}  // namespace ccomm
