// SPDX-License-Identifier: Apache-2.0
#include "store/segment.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <new>

#include "common/platform.h"
#include "common/value_type.h"

namespace ccomm {
namespace store {

StateView Segment::state(uint32_t id) const {
  const SignalDirectoryEntry& d = dir(id);
  StateView v;
  v.cell = At<StateCell>(base_, d.data_offset);
  v.slots = At<uint8_t>(base_, d.data_offset + sizeof(StateCell));
  v.slot_bytes = d.slot_bytes;
  v.value_bytes = d.value_bytes;
  return v;
}

RingView Segment::ring(uint32_t id) const {
  const SignalDirectoryEntry& d = dir(id);
  RingView v;
  v.ring = At<EventRing>(base_, d.data_offset);
  v.slots = At<uint8_t>(base_, d.data_offset + sizeof(EventRing));
  v.slot_bytes = d.slot_bytes;
  v.value_bytes = d.value_bytes;
  v.depth = d.queue_depth;
  v.backpressure = (d.flags & kSigForwarded) != 0;
  return v;
}

RingView Segment::history(uint32_t id) const {
  const SignalDirectoryEntry& d = dir(id);
  RingView v;
  if (!d.history_offset) return v;
  v.ring = At<EventRing>(base_, d.history_offset);
  v.slots = At<uint8_t>(base_, d.history_offset + sizeof(EventRing));
  v.slot_bytes = d.slot_bytes;
  v.value_bytes = d.value_bytes;
  v.depth = d.history_depth;
  v.backpressure = false;  // the oldest value is overwritten; a lagging reader counts its overrun
  return v;
}

const uint8_t* Segment::safe_value(uint32_t id) const {
  const SignalDirectoryEntry& d = dir(id);
  return d.safe_value_offset ? At<uint8_t>(base_, d.safe_value_offset) : nullptr;
}

int Segment::Find(const char* name) const {
  for (uint32_t i = 0; i < signal_count(); ++i)
    if (strncmp(dir(i).name, name, kNameBytes) == 0) return static_cast<int>(i);
  return -1;
}

void Segment::RingTxDoorbell() const {
  SegmentHeader* h = header();
  h->tx_doorbell.fetch_add(1, std::memory_order_seq_cst);
  if (h->tx_sleeping.load(std::memory_order_seq_cst)) platform::FutexWake(&h->tx_doorbell, 1);
}

void Segment::NotifyTx(uint32_t id, bool wake) const {
  MarkDirty(id);
  if (wake) {
    RingTxDoorbell();
  } else {
    header()->tx_doorbell.fetch_add(1, std::memory_order_release);
  }
}

void Segment::NotifyRx() const {
  SegmentHeader* h = header();
  // The caller's store published with a seq_cst RMW; this load is ordered after it.
  if (!h->rx_waiters.load(std::memory_order_seq_cst)) return;
  h->rx_doorbell.fetch_add(1, std::memory_order_seq_cst);
  platform::FutexWake(&h->rx_doorbell, 1 << 30);
}

int Segment::Open(const std::string& name) {
  Close();
  int fd = platform::ShmOpen(name.c_str(), false, 0);
  if (fd < 0) return fd;
  size_t size = 0;
  int r = platform::FileSize(fd, &size);
  if (r == 0 && size < sizeof(SegmentHeader)) r = -ENOENT;  // being created
  void* p = r == 0 ? platform::MapShared(fd, size) : nullptr;
  if (r == 0 && !p) r = -errno;
  platform::CloseFd(fd);
  if (r != 0) return r;
  auto* h = static_cast<SegmentHeader*>(p);
  if (h->state.load(std::memory_order_acquire) == kRetired) {
    // Opened just before ccommd unlinked it: the replacement is on its way. Checked before
    // the magic, which a damaged segment (the reason it is being replaced) may not have.
    platform::Unmap(p, size);
    return -ENOENT;
  }
  if (h->magic == 0) {
    // ccommd is creating it: ftruncate zero-fills, the header is copied in next. Not a
    // foreign segment; a client retrying now must not give up with "version mismatch".
    platform::Unmap(p, size);
    return -ENOENT;
  }
  if (h->magic != kSegmentMagic || h->layout_version != kLayoutVersion || h->size != size) {
    platform::Unmap(p, size);
    return -EPROTO;
  }
  if (h->state.load(std::memory_order_acquire) != kReady) {
    platform::Unmap(p, size);
    return -ENOENT;
  }
  if (!CheckLayout(p, size).empty()) {
    platform::Unmap(p, size);
    return -EPROTO;
  }
  base_ = p;
  size_ = size;
  platform::FutexPrepare(&header()->tx_doorbell);  // the doorbells' set-up, before any write
  platform::FutexPrepare(&header()->rx_doorbell);
  if (CopyLayout(p) != 0) {
    Close();
    return -ENOMEM;
  }
  return 0;
}

void Segment::Close() {
  if (base_) platform::Unmap(base_, size_);
  base_ = nullptr;
  size_ = 0;
  FreeLayout();
}

void Segment::FreeLayout() {
  delete[] layout_.directory;
  delete[] layout_.node_names;
  layout_ = Layout();
}

int Segment::CopyLayout(const void* trusted) {
  FreeLayout();
  const auto* h = static_cast<const SegmentHeader*>(trusted);
  layout_.signal_count = h->signal_count;
  layout_.node_count = h->node_count;
  layout_.node_id = h->node_id;
  layout_.signal_stats_offset = h->signal_stats_offset;
  layout_.peer_stats_offset = h->peer_stats_offset;
  layout_.dirty_offset = h->dirty_offset;
  layout_.directory = new (std::nothrow) SignalDirectoryEntry[h->signal_count ? h->signal_count : 1];
  layout_.node_names = new (std::nothrow) char[(h->node_count ? h->node_count : 1) * kNameBytes];
  if (!layout_.directory || !layout_.node_names) {
    FreeLayout();
    return -ENOMEM;
  }
  memcpy(static_cast<void*>(layout_.directory), At<char>(trusted, h->directory_offset),
         h->signal_count * sizeof(SignalDirectoryEntry));
  memcpy(layout_.node_names, At<char>(trusted, h->node_names_offset), h->node_count * kNameBytes);
  for (uint32_t i = 0; i < h->signal_count; ++i) layout_.directory[i].name[kNameBytes - 1] = '\0';
  for (uint32_t i = 0; i < h->node_count; ++i) layout_.node_names[i * kNameBytes + kNameBytes - 1] = '\0';
  return 0;
}

std::string CheckLayout(const void* base, size_t size) {
  const auto* h = static_cast<const SegmentHeader*>(base);
  auto within = [size](uint64_t off, uint64_t bytes) { return off <= size && bytes <= size - off; };
  const uint64_t n = h->signal_count, m = h->node_count;
  if (n > 65536 || m == 0 || m > 65536 || h->node_id >= m) return "signal/node counts out of range";
  if (!within(h->directory_offset, n * sizeof(SignalDirectoryEntry)) || !within(h->node_names_offset, m * kNameBytes) ||
      !within(h->signal_stats_offset, n * sizeof(SignalStats)) || !within(h->peer_stats_offset, m * sizeof(PeerStats)) ||
      !within(h->dirty_offset, (n + 63) / 64 * 8) || h->signal_stats_offset % kCacheLine ||
      h->peer_stats_offset % kCacheLine || h->dirty_offset % 8)
    return "a table lies outside the segment";
  for (uint64_t i = 0; i < n; ++i) {
    const SignalDirectoryEntry& d = At<SignalDirectoryEntry>(base, h->directory_offset)[i];
    const bool event = (d.flags & kSigEvent) != 0;
    const size_t esize = ValueTypeSize(d.type);
    if (esize == 0 || d.count == 0 || d.value_bytes != d.count * esize || d.value_bytes > (1u << 20) ||
        d.slot_bytes < sizeof(SlotHeader) + d.value_bytes || d.slot_bytes % 8 || d.data_offset % kCacheLine)
      return "signal " + std::to_string(i) + ": bad type, size or slot";
    const uint64_t depth = event ? d.queue_depth : kStateSlots;
    if (depth == 0 || (event && (depth & (depth - 1))) || (!event && d.queue_depth != kStateSlots))
      return "signal " + std::to_string(i) + ": bad queue depth";
    const uint64_t head = event ? sizeof(EventRing) : sizeof(StateCell);
    if (!within(d.data_offset, head + depth * d.slot_bytes))
      return "signal " + std::to_string(i) + ": data outside the segment";
    if (d.safe_value_offset && !within(d.safe_value_offset, d.value_bytes))
      return "signal " + std::to_string(i) + ": safe value outside the segment";
    if (d.history_offset || d.history_depth) {
      const uint64_t hd = d.history_depth;
      if (event || hd < 2 || (hd & (hd - 1)) || d.history_offset % kCacheLine ||
          !within(d.history_offset, sizeof(EventRing) + hd * d.slot_bytes))
        return "signal " + std::to_string(i) + ": bad history ring";
    }
  }
  return "";
}

// Replacing a segment, in this order: the name first stops pointing at the old object,
// then the old object says "retired". A client told to reopen by that word then finds the
// new segment or nothing yet (-ENOENT: it waits), never the old one: for a damaged old
// segment that would be -EPROTO ("layout version differs") and the client would give up.
// Clients still attached keep their mapping of the unlinked object until they reopen.
static void UnlinkThenRetire(const std::string& name) {
  int fd = platform::ShmOpen(name.c_str(), false, 0);
  platform::ShmUnlink(name.c_str());  // also removes a half-created or foreign segment
  if (fd < 0) return;
  size_t size = 0;
  void* p = platform::FileSize(fd, &size) == 0 && size >= sizeof(SegmentHeader) ? platform::MapShared(fd, size) : nullptr;
  platform::CloseFd(fd);
  if (!p) return;
  SegmentHeader* h = static_cast<SegmentHeader*>(p);
  h->state.store(kRetired, std::memory_order_release);
  // Wakes clients asleep in ccomm_wait() on the old object: nothing else would ring it
  // again, so they would sleep on forever instead of returning CCOMM_E_RETIRED.
  h->rx_doorbell.fetch_add(1, std::memory_order_seq_cst);
  platform::FutexWake(&h->rx_doorbell, 1 << 30);
  platform::Unmap(p, size);
}

// Compares the immutable part (header identity, directory, names, safe values) of an
// existing segment with what this configuration would build.
static bool SameLayout(const void* existing, const void* planned, size_t size) {
  auto* a = static_cast<const SegmentHeader*>(existing);
  auto* b = static_cast<const SegmentHeader*>(planned);
  if (a->magic != b->magic || a->layout_version != b->layout_version || a->size != b->size ||
      a->config_hash != b->config_hash || a->node_id != b->node_id ||
      a->signal_count != b->signal_count || a->node_count != b->node_count)
    return false;
  if (memcmp(At<char>(existing, b->directory_offset), At<char>(planned, b->directory_offset),
             b->signal_stats_offset - b->directory_offset) != 0)
    return false;
  for (uint32_t i = 0; i < b->signal_count; ++i) {
    const auto& d = At<SignalDirectoryEntry>(planned, b->directory_offset)[i];
    if (d.safe_value_offset && memcmp(At<char>(existing, d.safe_value_offset),
                                      At<char>(planned, d.safe_value_offset), d.value_bytes) != 0)
      return false;
  }
  (void)size;
  return true;
}

int Segment::CreateOrAdopt(const void* plan, size_t size, const std::string& name, int gid, bool* adopted,
                           std::string* error) {
  Close();
  *adopted = false;

  Segment old;
  int r = old.Open(name);
  if (r == 0 && old.size() == size && SameLayout(old.base(), plan, size)) {
    base_ = old.base_;
    size_ = old.size_;
    old.base_ = nullptr;
    if (CopyLayout(plan) != 0) {
      Close();
      return -ENOMEM;
    }
    header()->generation.fetch_add(1, std::memory_order_acq_rel);
    *adopted = true;
    return 0;
  }
  // A different configuration, a damaged or foreign segment, or none: replace it.
  old.Close();
  UnlinkThenRetire(name);
  int fd = platform::ShmOpen(name.c_str(), true, 0660);
  if (fd < 0) {
    *error = "cannot create shared memory " + name + ": " + strerror(-fd);
    return fd;
  }
  if (gid >= 0 && (r = platform::ShmSetGroup(fd, gid)) != 0)
    Log(LogLevel::kWarning, "cannot give %s to group %d: %s", name.c_str(), gid, strerror(-r));
  r = platform::Truncate(fd, size);
  void* p = r == 0 ? platform::MapShared(fd, size) : nullptr;
  if (r == 0 && !p) r = -errno;
  platform::CloseFd(fd);
  if (r != 0) {
    platform::ShmUnlink(name.c_str());
    *error = "cannot size/map shared memory " + name + ": " + strerror(-r);
    return r;
  }
  memcpy(p, plan, size);
  base_ = p;
  size_ = size;
  platform::FutexPrepare(&header()->tx_doorbell);  // the doorbells' set-up, before any write
  platform::FutexPrepare(&header()->rx_doorbell);
  if (CopyLayout(plan) != 0) {
    Close();
    platform::ShmUnlink(name.c_str());
    return -ENOMEM;
  }
  header()->generation.store(1, std::memory_order_relaxed);
  header()->state.store(kReady, std::memory_order_release);
  return 0;
}

}  // namespace store
}  // namespace ccomm
