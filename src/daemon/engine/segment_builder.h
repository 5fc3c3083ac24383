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
/// "" if node `node_id`'s segment (named `name`) can be created on this machine, else a
/// one-line cause with the fix: room in /dev/shm (not needed to re-adopt a segment of the
/// same size), the cgroup's memory.max and RLIMIT_AS (twice the size: the image is built
/// in memory first), the address space. Checked by --check and before creating it.
std::string SegmentFitProblem(const SystemConfig& cfg, uint32_t node_id, const std::string& name);
/// Takes node `segment_name`'s lock: a POSIX record lock on the shared-memory object
/// "<segment_name>.lock", held as long as this process lives, also while it is stopped
/// (SIGSTOP: a heartbeat would stand still), and dropped by the kernel when it dies
/// (SIGKILL, crash), so a restart never waits. The object is never removed: removing it
/// would let two daemons lock two different files. Returns the fd to keep open (>= 0);
/// -EBUSY if another process holds it (its pid in *holder_pid when the kernel says);
/// another -errno if the object cannot be opened.
int LockNode(const std::string& segment_name, int gid, int* holder_pid);
/// Builds the image and creates or re-adopts the segment `name` from it (see
/// store::Segment::CreateOrAdopt).
int CreateOrAdoptSegment(store::Segment* segment, const SystemConfig& cfg, uint32_t node_id,
                         const std::string& name, int gid, bool* adopted, std::string* error);

}  // namespace ccomm
