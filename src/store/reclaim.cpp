// SPDX-License-Identifier: Apache-2.0
#include "store/reclaim.h"

#include "common/platform.h"

namespace ccomm {
namespace store {

namespace {

// Calls fn(slot header, cell) for every slot; cell is set for a state cell's inline
// claim (the same seq/owner protocol: 0 frees it like a slot), null otherwise.
template <typename Fn>
void ForEachSlot(const Segment& s, Fn fn) {
  for (uint32_t id = 0; id < s.signal_count(); ++id) {
    const SignalDirectoryEntry& d = s.dir(id);
    if (d.flags & kSigEvent) {
      RingView r = s.ring(id);
      for (uint32_t i = 0; i < r.depth; ++i) fn(r.slot(i), static_cast<const StateView*>(nullptr));
    } else {
      StateView v = s.state(id);
      for (uint32_t i = 0; i < kStateSlots; ++i) fn(v.slot(i), static_cast<const StateView*>(nullptr));
      fn(&v.cell->inline_claim, &v);
    }
  }
}

// A writer that died holding a cell's inline claim for ticket t had completed its slot
// and may have filled the readers' line copy, but not published `latest`. Readers may
// already have taken that copy; once the claim is free and the copy is refilled they
// fall back to the slot of `latest`, which would be older. So publish ticket t first,
// as its writer would have, if its slot still holds it complete.
void PublishDeadInlineWriter(const StateView& v, uint64_t t) {
  if (v.slot(t)->seq.load(std::memory_order_acquire) != 2 * t + 2) return;
  PublishLatest(v, t);
}

}  // namespace

size_t SlotCount(const Segment& s) {
  size_t n = 0;
  ForEachSlot(s, [&](SlotHeader*, const StateView*) { n++; });
  return n;
}

size_t ReclaimAbandonedSlots(const Segment& s, std::vector<SlotSuspect>* suspects) {
  size_t i = 0, reclaimed = 0;
  ForEachSlot(s, [&](SlotHeader* h, const StateView* cell) {
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
      if (cell) PublishDeadInlineWriter(*cell, ticket);
      uint64_t expected = seq;
      if (h->seq.compare_exchange_strong(expected, 0, std::memory_order_acq_rel)) reclaimed++;
      prev = SlotSuspect();
    }
  });
  return reclaimed;
}

WaiterEntry* ClaimWaiterEntry(SegmentHeader* h, uint32_t pid) {
  WaiterEntry* free_entry = nullptr;
  for (WaiterEntry& e : h->waiters) {
    const uint32_t owner = e.pid.load(std::memory_order_acquire);
    if (owner == pid) return &e;
    if (owner == 0 && !free_entry) free_entry = &e;
  }
  for (WaiterEntry* e = free_entry; e && e < h->waiters + kWaiterEntries; ++e) {
    uint32_t expected = 0;
    if (e->pid.compare_exchange_strong(expected, pid, std::memory_order_acq_rel)) return e;
    if (expected == pid) return e;  // another thread of this process claimed it first
  }
  return nullptr;
}

uint32_t ReclaimDeadWaiters(SegmentHeader* h) {
  uint32_t taken = 0;
  for (WaiterEntry& e : h->waiters) {
    const uint32_t pid = e.pid.load(std::memory_order_acquire);
    if (pid == 0 || platform::ProcessAlive(pid)) continue;
    // Gone: nothing of it changes `waiting` any more.
    const uint32_t n = e.waiting.exchange(0, std::memory_order_acq_rel);
    if (n) h->rx_waiters.fetch_sub(n, std::memory_order_seq_cst);
    taken += n;
    e.pid.store(0, std::memory_order_release);
  }
  return taken;
}

}  // namespace store
}  // namespace ccomm
