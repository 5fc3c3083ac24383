// SPDX-License-Identifier: Apache-2.0
// Gives back slots left "being written" by writers that died (kill -9 mid-write).
//
// A slot is odd while its writer copies the value. If the writer dies, the slot stays
// odd: state cells lose one of their kStateSlots copies, event rings get a hole every
// lap. ccommd calls ReclaimAbandonedSlots about once a second. A slot is freed (seq -> 0,
// which readers never accept and writers may claim) only when its writer is provably
// gone: the owner word names a pid that no longer exists, or the writer died before it
// could write the owner word (the slot was odd with the same seq at the previous scan
// and its owner word names an older ticket). A slow but live writer is never touched,
// so its late stores can never land in a reused slot.
#pragma once

#include <cstdint>
#include <vector>

#include "store/segment.h"

namespace ccomm {
namespace store {

/// Per-slot memory between scans; size it once with SlotCount() (start-up only).
size_t SlotCount(const Segment& s);

/// Scans every slot; returns how many were reclaimed. `suspects` must have
/// SlotCount(s) entries (zeros initially). Makes one kill(pid, 0) per odd slot.
size_t ReclaimAbandonedSlots(const Segment& s, std::vector<uint64_t>* suspects);

}  // namespace store
}  // namespace ccomm
