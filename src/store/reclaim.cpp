// SPDX-License-Identifier: Apache-2.0
#include "store/reclaim.h"

#include "common/platform.h"

namespace ccomm {
namespace store {

namespace {

template <typename Fn>
void ForEachSlot(const Segment& s, Fn fn) {
  for (uint32_t id = 0; id < s.signal_count(); ++id) {
    const SignalDirectoryEntry& d = s.dir(id);
    if (d.flags & kSigEvent) {
      RingView r = s.ring(id);
      for (uint32_t i = 0; i < r.depth; ++i) fn(r.slot(i));
    } else {
      StateView v = s.state(id);
      for (uint32_t i = 0; i < kStateSlots; ++i) fn(v.slot(i));
      fn(&v.cell->inline_claim);  // same protocol; 0 frees it like a slot
    }
  }
}

}  // namespace

size_t SlotCount(const Segment& s) {
  size_t n = 0;
  ForEachSlot(s, [&](SlotHeader*) { n++; });
  return n;
}

size_t ReclaimAbandonedSlots(const Segment& s, std::vector<SlotSuspect>* suspects) {
  size_t i = 0, reclaimed = 0;
  ForEachSlot(s, [&](SlotHeader* h) {
    SlotSuspect& prev = (*suspects)[i++];
    uint64_t seq = h->seq.load(std::memory_order_acquire);
    if (!(seq & 1)) {
      prev = SlotSuspect();
      return;
    }
    uint64_t ticket = (seq - 1) / 2;
    uint64_t owner = h->owner.load(std::memory_order_acquire);
    bool owner_known = (owner & 0xffffffffu) == (ticket & 0xffffffffu);
    prev.scans = (!owner_known && prev.seq == seq) ? prev.scans + 1 : 0;
    prev.seq = seq;
    bool dead = owner_known ? !platform::ProcessAlive(static_cast<uint32_t>(owner >> 32))
                            : prev.scans >= kUnknownOwnerScans;  // claimed, owner never written
    if (dead) {
      uint64_t expected = seq;
      if (h->seq.compare_exchange_strong(expected, 0, std::memory_order_acq_rel)) reclaimed++;
      prev = SlotSuspect();
    }
  });
  return reclaimed;
}

}  // namespace store
}  // namespace ccomm
