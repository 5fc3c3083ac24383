// SPDX-License-Identifier: Apache-2.0
// A node's shared-memory segment: created (or re-adopted) by ccommd from an image it
// builds from the configuration (daemon/engine/segment_builder.h), mapped by clients. See
// layout.h for the invariants. The store knows nothing of the configuration.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "common/public/platform_app.h"
#include "store/event_ring.h"
#include "store/layout.h"
#include "store/state_slot.h"

namespace ccomm {
namespace store {

/// POSIX shm name of a node's segment: $CCOMM_SHM_PREFIX (default "/ccomm.") + node,
/// built by the platform layer (common/public/platform_app.h) for every user of the name.
using platform::SegmentName;

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
  /// not ready yet, or retired: being replaced), -EPROTO (bad magic/layout version/size)
  /// or another -errno.
  int Open(const std::string& name);

  void Close();
  bool is_open() const { return base_ != nullptr; }

  // The layout (counts, offsets, directory, node names) is copied into this process
  // when the segment is created or opened (and checked then): clients can write over
  // the whole mapping, and nobody may follow an offset or index read from it afterwards.
  SegmentHeader* header() const { return static_cast<SegmentHeader*>(base_); }
  uint32_t signal_count() const { return layout_.signal_count; }
  uint32_t node_count() const { return layout_.node_count; }
  uint32_t node_id() const { return layout_.node_id; }
  const SignalDirectoryEntry& dir(uint32_t id) const { return layout_.directory[id]; }
  const char* node_name(uint32_t node) const { return layout_.node_names + node * kNameBytes; }
  SignalStats& stats(uint32_t id) const { return At<SignalStats>(base_, layout_.signal_stats_offset)[id]; }
  PeerStats& peer(uint32_t node) const { return At<PeerStats>(base_, layout_.peer_stats_offset)[node]; }
  std::atomic<uint64_t>* dirty_words() const { return At<std::atomic<uint64_t>>(base_, layout_.dirty_offset); }
  StateView state(uint32_t id) const;
  RingView ring(uint32_t id) const;
  /// The history ring of a received state signal (layout.h); ring == nullptr if none.
  RingView history(uint32_t id) const;
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
  /// A batch step's stores: between BeginStep and EndStep (see SegmentHeader::steps_active).
  void BeginStep() const { header()->steps_active.fetch_add(1, std::memory_order_seq_cst); }
  void EndStep() const {
    header()->steps_done.fetch_add(1, std::memory_order_release);
    header()->steps_active.fetch_sub(1, std::memory_order_release);
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
  // A private copy of what only ccommd may change (see above).
  struct Layout {
    uint32_t signal_count = 0, node_count = 0, node_id = 0;
    uint64_t signal_stats_offset = 0, peer_stats_offset = 0, dirty_offset = 0;
    SignalDirectoryEntry* directory = nullptr;
    char* node_names = nullptr;
  };
  /// Copies the layout of `trusted` (the daemon's own image, or a mapping that passed
  /// CheckLayout) into layout_; -ENOMEM on failure.
  int CopyLayout(const void* trusted);
  void FreeLayout();

  void* base_ = nullptr;
  size_t size_ = 0;
  Layout layout_;
};

/// Checks that every offset and size in a mapped segment's header and directory stays
/// inside its `size` bytes and is consistent (a damaged or foreign segment is refused at
/// open instead of being followed). Returns "" or what is wrong.
std::string CheckLayout(const void* base, size_t size);

}  // namespace store
}  // namespace ccomm
