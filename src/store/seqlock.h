// SPDX-License-Identifier: Apache-2.0
// The one seqlock sequence of the store: claim, stamp, publish (writer) and copy,
// check (reader). Slots of state cells, slots of event rings and the state cells'
// inline copies all hold a value this way; state_slot.h and event_ring.h decide which
// ticket goes where, this file is how one copy is written and read.
//
// A copy is a sequence word, four meta words (value_seq, source time, local time, check)
// and the value, padded to 8 bytes. Sequence word for ticket t: 2t+1 while being written,
// 2t+2 when complete. `check` is a hash of the other meta words and the value: shared
// memory is writable by every client of the node, and a stray write (a buggy model's
// pointer) that leaves the sequence word plausible must not turn into a value readers
// take as fresh. It detects damage, not forgery: a client that writes a plausible value
// with its check is a producer, trusted by design (docs/reliability.md). Invariants:
//   - A copy is claimed only from an even sequence word not newer than 2t (a CAS), so
//     two writers never fill one copy and a copy never goes back to an older ticket.
//   - A reader accepts a copy only if the sequence word is 2t+2 before and after
//     taking it; the fences in word_copy.h order the data between the two looks.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>

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

/// The check of one copy: an odd-multiplier chain over meta and value words (zero-padded
/// tail). Each step (xor a word, multiply by an odd constant) is a bijection of the running
/// value, so a change to any one word always changes the check; random damage to several
/// passes with probability ~2^-64. Cheap on purpose: it runs on every read of a new value.
inline uint64_t CopyCheck(const SlotMeta& meta, const void* value, uint32_t value_bytes) {
  constexpr uint64_t kOdd = 0x9e3779b97f4a7c15ull;
  uint64_t h = (meta.value_seq ^ (uint64_t{value_bytes} << 48)) * kOdd;
  h = (h ^ meta.source_time_ns) * kOdd;
  h = (h ^ meta.local_time_ns) * kOdd;
  const uint8_t* p = static_cast<const uint8_t*>(value);
  if (value_bytes == 8) {  // the common value: the loop below, unrolled
    uint64_t w;
    memcpy(&w, p, 8);
    h = (h ^ w) * kOdd;
    return h ^ (h >> 31);
  }
  uint32_t i = 0;
  for (; i + 8 <= value_bytes; i += 8) {
    uint64_t w;
    memcpy(&w, p + i, 8);
    h = (h ^ w) * kOdd;
  }
  if (i < value_bytes) {
    uint64_t w = 0;
    memcpy(&w, p + i, value_bytes - i);
    h = (h ^ w) * kOdd;
  }
  return h ^ (h >> 31);
}

/// What a reader found in a copy.
enum class CopyResult { kOk, kChanged, kCorrupt };

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
/// `check` is CopyCheck(meta, value, value_bytes), computed once by a writer that stores
/// the same value twice (a state's slot and its inline copy).
inline void StampCheckedAndPublish(std::atomic<uint64_t>* seq, std::atomic<uint64_t>* meta4, uint8_t* data,
                                   uint64_t t, uint32_t value_bytes, const void* value, const SlotMeta& meta,
                                   uint64_t check) {
  SeqlockWriterFence();
  meta4[0].store(meta.value_seq, kMetaStore);
  meta4[1].store(meta.source_time_ns, kMetaStore);
  meta4[2].store(meta.local_time_ns, kMetaStore);
  meta4[3].store(check, kMetaStore);
  StoreWords(data, value, value_bytes);
  seq->store(2 * t + 2, std::memory_order_release);
}
inline void StampAndPublish(std::atomic<uint64_t>* seq, std::atomic<uint64_t>* meta4, uint8_t* data, uint64_t t,
                            uint32_t value_bytes, const void* value, const SlotMeta& meta) {
  StampCheckedAndPublish(seq, meta4, data, t, value_bytes, value, meta, CopyCheck(meta, value, value_bytes));
}

/// The rest of ReadCopy, for a reader that already loaded (with acquire order) the
/// sequence word s1, even and the ticket it wants: the stamp a cached reader compares
/// is that same word, so a new value costs no second look before the copy.
__attribute__((always_inline)) inline CopyResult ReadCopyAt(const std::atomic<uint64_t>* seq, uint64_t s1,
                                                           const std::atomic<uint64_t>* meta4, const uint8_t* data,
                                                           uint32_t value_bytes, void* out, SlotMeta* meta) {
  meta->value_seq = meta4[0].load(kMetaLoad);
  meta->source_time_ns = meta4[1].load(kMetaLoad);
  meta->local_time_ns = meta4[2].load(kMetaLoad);
  const uint64_t check = meta4[3].load(kMetaLoad);
  LoadWords(out, data, value_bytes);
  SeqlockReaderFence();
  if (seq->load(std::memory_order_relaxed) != s1) return CopyResult::kChanged;
  return check == CopyCheck(*meta, out, value_bytes) ? CopyResult::kOk : CopyResult::kCorrupt;
}

/// Copies a seqlocked value if it holds complete ticket t: kChanged if not (yet) or if
/// it changed while being copied, kCorrupt if it stayed put but fails its check.
__attribute__((always_inline)) inline CopyResult ReadCopy(const std::atomic<uint64_t>* seq,
                                                         const std::atomic<uint64_t>* meta4, const uint8_t* data,
                                                         uint64_t t, uint32_t value_bytes, void* out, SlotMeta* meta) {
  uint64_t s1 = seq->load(std::memory_order_acquire);
  if (s1 != 2 * t + 2) return CopyResult::kChanged;
  return ReadCopyAt(seq, s1, meta4, data, value_bytes, out, meta);
}

/// A slot's copy (the value follows its header).
inline void PublishSlot(SlotHeader* slot, uint64_t t, uint32_t value_bytes, const void* value, const SlotMeta& meta) {
  StampAndPublish(&slot->seq, &slot->value_seq, reinterpret_cast<uint8_t*>(slot + 1), t, value_bytes, value, meta);
}
__attribute__((always_inline)) inline CopyResult ReadSlot(const SlotHeader* slot, uint64_t t, uint32_t value_bytes,
                                                         void* out, SlotMeta* meta) {
  return ReadCopy(&slot->seq, &slot->value_seq, reinterpret_cast<const uint8_t*>(slot + 1), t, value_bytes, out, meta);
}

}  // namespace store
}  // namespace ccomm
