// SPDX-License-Identifier: Apache-2.0
// Gives back slots left "being written" by writers that died (kill -9 mid-write).
//
// A slot is odd while its writer copies the value. If the writer dies, the slot stays
// odd: state cells lose one of their kStateSlots copies, event rings get a hole every
// lap. ccommd calls ReclaimAbandonedSlots about once a second. A slot is freed (seq -> 0,
// which readers never accept and writers may claim) only when its writer is gone: the
// owner word names a pid that no longer exists, or the writer died before it could
// write the owner word (owner names an older ticket, and the slot stayed odd with the
// same seq for kUnknownOwnerScans scans, i.e. seconds, for two instructions' work).
// A slow but live writer is not touched, so its late stores never land in a reused slot.
// A state cell's inline claim is reclaimed the same way, after publishing the dead
// holder's ticket if its slot is complete (readers may have seen its line copy).
// Limit: pids are those of ccommd's pid namespace; writers in another pid namespace
// (a container with its own) must not share a segment with this ccommd.
#pragma once

#include <cstdint>
#include <vector>

#include "store/segment.h"

namespace ccomm {
namespace store {

/// What a scan remembers of one slot for the next.
struct SlotSuspect {
  uint64_t seq = 0;    // odd seq seen, 0 = slot was not odd
  uint32_t scans = 0;  // consecutive scans it was seen odd with that seq and no owner
};
constexpr uint32_t kUnknownOwnerScans = 5;

/// Number of slots in the segment; size the suspects vector with it (start-up only).
size_t SlotCount(const Segment& s);

/// Scans every slot; returns how many were reclaimed. `suspects` must have
/// SlotCount(s) entries. Makes one kill(pid, 0) per odd slot with a known owner.
size_t ReclaimAbandonedSlots(const Segment& s, std::vector<SlotSuspect>* suspects);

/// The waiter entry (layout.h, WaiterEntry) of process `pid`, claimed if it has none;
/// nullptr when all are taken by live or not yet reclaimed processes. Client side, as a
/// wait begins (a scan of kWaiterEntries entries, no system call).
WaiterEntry* ClaimWaiterEntry(SegmentHeader* h, uint32_t pid);
/// ccommd, about once a second: for each entry whose process is gone, its waits are taken
/// back from rx_waiters and the entry freed. Returns the waits taken back. One
/// kill(pid, 0) per claimed entry. A process killed between registering in rx_waiters and
/// in its entry (two instructions) leaves one wait behind, as before this existed.
uint32_t ReclaimDeadWaiters(SegmentHeader* h);

}  // namespace store
}  // namespace ccomm
