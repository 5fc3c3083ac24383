// SPDX-License-Identifier: Apache-2.0
#include "store/segment.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <new>

#include "common/platform.h"

namespace ccomm {
namespace store {

std::string SegmentName(const std::string& node) {
  const char* prefix = getenv("CCOMM_SHM_PREFIX");
  return std::string(prefix && *prefix ? prefix : "/ccomm.") + node;
}

namespace {

struct Plan {
  size_t directory, node_names, signal_stats, peer_stats, dirty, data, total;
};

// Whole cache lines: a slot never shares a line with its neighbour, so a writer filling
// one slot does not pull the line a reader is copying the previous one from.
size_t SlotBytes(const SignalConfig& s) {
  return AlignUp(sizeof(SlotHeader) + AlignUp(s.value_bytes(), 8), kCacheLine);
}

size_t DataBytes(const SignalConfig& s) {
  size_t slots = s.kind == SignalKind::kEvent ? s.queue_depth : kStateSlots;
  size_t head = s.kind == SignalKind::kEvent ? sizeof(EventRing) : sizeof(StateCell);
  size_t safe = s.has_safe_value ? AlignUp(s.value_bytes(), 8) : 0;
  return AlignUp(head + slots * SlotBytes(s) + safe, kCacheLine);
}

Plan MakePlan(const SystemConfig& cfg) {
  Plan p;
  size_t n = cfg.signals.size(), m = cfg.nodes.size();
  p.directory = AlignUp(sizeof(SegmentHeader), kCacheLine);
  p.node_names = AlignUp(p.directory + n * sizeof(SignalDirectoryEntry), kCacheLine);
  p.signal_stats = AlignUp(p.node_names + m * kNameBytes, kCacheLine);
  p.peer_stats = p.signal_stats + n * sizeof(SignalStats);
  p.dirty = AlignUp(p.peer_stats + m * sizeof(PeerStats), kCacheLine);
  p.data = AlignUp(p.dirty + ((n + 63) / 64) * 8, kCacheLine);
  size_t off = p.data;
  for (const auto& s : cfg.signals) off += DataBytes(s);
  p.total = AlignUp(off, 4096);
  return p;
}

}  // namespace

size_t SegmentSize(const SystemConfig& cfg) { return MakePlan(cfg).total; }

void BuildSegment(const SystemConfig& cfg, uint32_t node_id, void* mem, size_t size) {
  Plan p = MakePlan(cfg);
  memset(mem, 0, size);
  auto* h = new (mem) SegmentHeader();
  h->magic = kSegmentMagic;
  h->layout_version = kLayoutVersion;
  h->size = p.total;
  h->config_hash = cfg.hash;
  h->node_id = node_id;
  h->signal_count = static_cast<uint32_t>(cfg.signals.size());
  h->node_count = static_cast<uint32_t>(cfg.nodes.size());
  h->directory_offset = p.directory;
  h->node_names_offset = p.node_names;
  h->signal_stats_offset = p.signal_stats;
  h->peer_stats_offset = p.peer_stats;
  h->dirty_offset = p.dirty;
  snprintf(h->node_name, kNameBytes, "%s", cfg.nodes[node_id].name.c_str());
  for (size_t i = 0; i < cfg.nodes.size(); ++i)
    snprintf(At<char>(mem, p.node_names) + i * kNameBytes, kNameBytes, "%s", cfg.nodes[i].name.c_str());

  size_t off = p.data;
  for (size_t i = 0; i < cfg.signals.size(); ++i) {
    const SignalConfig& s = cfg.signals[i];
    auto& d = At<SignalDirectoryEntry>(mem, p.directory)[i];
    snprintf(d.name, kNameBytes, "%s", s.name.c_str());
    d.id = static_cast<uint32_t>(i);
    bool event = s.kind == SignalKind::kEvent;
    bool produced = s.producer == node_id;
    bool remote_consumer = false, consumed_here = false;
    for (uint32_t c : s.consumers) {
      if (c == node_id) consumed_here = true;
      else remote_consumer = true;
    }
    uint32_t f = 0;
    if (event) f |= kSigEvent;
    if (produced) f |= kSigProducedHere;
    if (produced && remote_consumer) f |= kSigForwarded;
    if (!produced && consumed_here) f |= kSigConsumedHere;
    if (s.has_safe_value) f |= kSigHasSafeValue;
    if (s.period_us) f |= kSigPeriodic;
    d.flags = f;
    d.type = static_cast<uint8_t>(s.type);
    d.count = s.count;
    d.value_bytes = static_cast<uint32_t>(s.value_bytes());
    d.slot_bytes = static_cast<uint32_t>(SlotBytes(s));
    d.producer = s.producer;
    d.stale_after_ms = s.stale_after_ms;
    d.period_us = s.period_us;
    d.queue_depth = event ? s.queue_depth : kStateSlots;
    d.data_offset = off;
    size_t head = event ? sizeof(EventRing) : sizeof(StateCell);
    size_t slots = event ? s.queue_depth : kStateSlots;
    if (s.has_safe_value) {
      d.safe_value_offset = off + head + slots * d.slot_bytes;
      memcpy(At<uint8_t>(mem, d.safe_value_offset), s.safe_value.data(), s.value_bytes());
    }
    off += DataBytes(s);
  }
  h->state.store(kInitializing, std::memory_order_relaxed);
}

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
  base_ = p;
  size_ = size;
  return 0;
}

void Segment::Close() {
  if (base_) platform::Unmap(base_, size_);
  base_ = nullptr;
  size_ = 0;
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

int Segment::CreateOrAdopt(const SystemConfig& cfg, uint32_t node_id, const std::string& name,
                           int gid, bool* adopted, std::string* error) {
  Close();
  *adopted = false;
  size_t size = SegmentSize(cfg);
  void* plan = calloc(1, size);
  if (!plan) return -ENOMEM;
  BuildSegment(cfg, node_id, plan, size);

  Segment old;
  int r = old.Open(name);
  if (r == 0 && old.size() == size && SameLayout(old.base(), plan, size)) {
    free(plan);
    base_ = old.base_;
    size_ = old.size_;
    old.base_ = nullptr;
    header()->generation.fetch_add(1, std::memory_order_acq_rel);
    *adopted = true;
    return 0;
  }
  if (r == 0) {
    // Different configuration: tell clients to reopen, then replace it.
    old.header()->state.store(kRetired, std::memory_order_release);
    old.Close();
  }
  platform::ShmUnlink(name.c_str());  // also removes a half-created or foreign segment
  int fd = platform::ShmOpen(name.c_str(), true, 0660);
  if (fd < 0) {
    free(plan);
    *error = "cannot create shared memory " + name + ": " + strerror(-fd);
    return fd;
  }
  if (gid >= 0 && fchown(fd, static_cast<uid_t>(-1), static_cast<gid_t>(gid)) != 0)
    Log(LogLevel::kWarning, "cannot give %s to group %d: %s", name.c_str(), gid, strerror(errno));
  r = platform::Truncate(fd, size);
  void* p = r == 0 ? platform::MapShared(fd, size) : nullptr;
  if (r == 0 && !p) r = -errno;
  platform::CloseFd(fd);
  if (r != 0) {
    free(plan);
    platform::ShmUnlink(name.c_str());
    *error = "cannot size/map shared memory " + name + ": " + strerror(-r);
    return r;
  }
  memcpy(p, plan, size);
  free(plan);
  base_ = p;
  size_ = size;
  header()->generation.store(1, std::memory_order_relaxed);
  header()->state.store(kReady, std::memory_order_release);
  return 0;
}

}  // namespace store
}  // namespace ccomm
