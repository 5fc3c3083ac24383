// SPDX-License-Identifier: Apache-2.0
// A node's shared-memory segment: created (or re-adopted) by ccommd from an image it
// builds from the configuration (daemon/segment_builder.h), mapped by clients. See
// layout.h for the invariants. The store knows nothing of the configuration.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "store/event_ring.h"
#include "store/layout.h"
#include "store/state_slot.h"

namespace ccomm {
namespace store {

/// POSIX shm name of a node's segment: $CCOMM_SHM_PREFIX (default "/ccomm.") + node.
std::string SegmentName(const std::string& node);

class Segment {
 public:
  Segment() = default;
  ~Segment() { Close(); }
  Segment(const Segment&) = delete;
  Segment& operator=(const Segment&) = delete;

  /// Daemon side. `image` (`size` bytes, state kInitializing) is the complete segment as
  /// the daemon built it. Re-adopts an existing segment with exactly that layout
  /// (clients keep running across a daemon restart); otherwise marks the old one
  /// retired, unlinks it and creates a fresh one from the image (mode 0660, group `gid`
  /// if >= 0). Returns 0 or -errno; `error` says what failed.
  int CreateOrAdopt(const void* image, size_t size, const std::string& name, int gid, bool* adopted,
                    std::string* error);

  /// Client side: maps an existing, ready segment. Returns 0, -ENOENT (no segment or
  /// not ready yet), -EPROTO (bad magic/layout version/size) or another -errno.
  int Open(const std::string& name);

  void Close();
  bool is_open() const { return base_ != nullptr; }

  SegmentHeader* header() const { return static_cast<SegmentHeader*>(base_); }
  uint32_t signal_count() const { return header()->signal_count; }
  uint32_t node_count() const { return header()->node_count; }
  const SignalDirectoryEntry& dir(uint32_t id) const {
    return At<SignalDirectoryEntry>(base_, header()->directory_offset)[id];
  }
  const char* node_name(uint32_t node) const {
    return At<char>(base_, header()->node_names_offset) + node * kNameBytes;
  }
  SignalStats& stats(uint32_t id) const {
    return At<SignalStats>(base_, header()->signal_stats_offset)[id];
  }
  PeerStats& peer(uint32_t node) const {
    return At<PeerStats>(base_, header()->peer_stats_offset)[node];
  }
  std::atomic<uint64_t>* dirty_words() const {
    return At<std::atomic<uint64_t>>(base_, header()->dirty_offset);
  }
  StateView state(uint32_t id) const;
  RingView ring(uint32_t id) const;
  const uint8_t* safe_value(uint32_t id) const;
  /// Signal id by name, or -1 (linear scan: start-up only).
  int Find(const char* name) const;

  /// Marks a forwarded signal changed (ccommd collects it at its next wake-up).
  void MarkDirty(uint32_t id) const {
    dirty_words()[id / 64].fetch_or(1ull << (id % 64), std::memory_order_release);
  }
  /// Marks the signals of dirty-map word `word` set in `bits` changed at once (a batch).
  void MarkDirtyWord(uint32_t word, uint64_t bits) const {
    dirty_words()[word].fetch_or(bits, std::memory_order_release);
  }
  /// Wakes ccommd's send thread if it sleeps (one FUTEX_WAKE only then).
  void RingTxDoorbell() const;
  /// MarkDirty, then bumps the doorbell, waking ccommd if `wake` (see layout.h).
  void NotifyTx(uint32_t id, bool wake) const;
  /// Wakes ccomm_wait() callers, if any (call after a StateWrite/RingWrite; see
  /// SegmentHeader::rx_waiters). No shared write when nobody waits.
  void NotifyRx() const;

  void* base() const { return base_; }
  size_t size() const { return size_; }

 private:
  void* base_ = nullptr;
  size_t size_ = 0;
};

}  // namespace store
}  // namespace ccomm
