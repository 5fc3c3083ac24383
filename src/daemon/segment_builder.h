// SPDX-License-Identifier: Apache-2.0
// Builds a node's shared-memory segment image from the configuration: the daemon's job
// (clients only map segments, the store only knows their layout).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "config/config.h"
#include "store/segment.h"

namespace ccomm {

/// Bytes of the segment `cfg` gives node `node_id` (whole pages).
size_t SegmentSize(const SystemConfig& cfg, uint32_t node_id);
/// Builds the complete segment image for `cfg` as seen by `node_id` into `mem` (size
/// from SegmentSize). Used for creation and to compare with an existing segment.
void BuildSegment(const SystemConfig& cfg, uint32_t node_id, void* mem, size_t size);
/// The pid of another ccommd that serves segment `name` now (its heartbeat advances
/// within 100 ms), else 0. A ccommd that stopped cleanly cleared its pid (no wait); a
/// killed one left it, and its heartbeat stands still: then this waits the 100 ms.
int RunningDaemonOf(const std::string& name);
/// Builds the image and creates or re-adopts the segment `name` from it (see
/// store::Segment::CreateOrAdopt).
int CreateOrAdoptSegment(store::Segment* segment, const SystemConfig& cfg, uint32_t node_id,
                         const std::string& name, int gid, bool* adopted, std::string* error);

}  // namespace ccomm
