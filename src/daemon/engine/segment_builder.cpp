// SPDX-License-Identifier: Apache-2.0
#include "daemon/engine/segment_builder.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <stdint.h>

#include <algorithm>
#include <memory>
#include <new>

#include "common/platform.h"

namespace ccomm {

using namespace store;  // the layout types this file fills in

namespace {

// 64-bit even on a 32-bit board: a configuration may ask for more than it can map
// (SegmentFitProblem says so instead of wrapping around).
struct Plan {
  uint64_t directory, node_names, signal_stats, peer_stats, dirty, data, total;
};

constexpr uint64_t AlignUp64(uint64_t v, uint64_t a) { return (v + a - 1) & ~(a - 1); }

// Whole cache lines: a slot never shares a line with its neighbour, so a writer filling
// one slot does not pull the line a reader is copying the previous one from.
size_t SlotBytes(const SignalConfig& s) {
  return AlignUp(sizeof(SlotHeader) + AlignUp(s.value_bytes(), 8), kCacheLine);
}

// Values of `s` node `node_id` keeps in a history ring (layout.h): states it receives,
// when the node asks for history; 0 otherwise.
uint32_t HistoryDepth(const SystemConfig& cfg, const SignalConfig& s, uint32_t node_id) {
  if (s.kind != SignalKind::kState || s.producer == node_id) return 0;
  bool consumed_here = false;
  for (uint32_t c : s.consumers) consumed_here |= c == node_id;
  return consumed_here ? cfg.nodes[node_id].history : 0;
}

uint64_t DataBytes(const SignalConfig& s, uint32_t history_depth) {
  uint64_t slots = s.kind == SignalKind::kEvent ? s.queue_depth : kStateSlots;
  uint64_t head = s.kind == SignalKind::kEvent ? sizeof(EventRing) : sizeof(StateCell);
  uint64_t safe = s.has_safe_value ? AlignUp(s.value_bytes(), 8) : 0;
  uint64_t history = history_depth ? sizeof(EventRing) + uint64_t{history_depth} * SlotBytes(s) : 0;
  return AlignUp64(head + slots * SlotBytes(s) + safe, kCacheLine) + history;
}

Plan MakePlan(const SystemConfig& cfg, uint32_t node_id) {
  Plan p;
  size_t n = cfg.signals.size(), m = cfg.nodes.size();
  p.directory = AlignUp(sizeof(SegmentHeader), kCacheLine);
  p.node_names = AlignUp(p.directory + n * sizeof(SignalDirectoryEntry), kCacheLine);
  p.signal_stats = AlignUp(p.node_names + m * kNameBytes, kCacheLine);
  p.peer_stats = p.signal_stats + n * sizeof(SignalStats);
  p.dirty = AlignUp(p.peer_stats + m * sizeof(PeerStats), kCacheLine);
  p.data = AlignUp(p.dirty + ((n + 63) / 64) * 8, kCacheLine);
  uint64_t off = p.data;
  for (const auto& s : cfg.signals) off += DataBytes(s, HistoryDepth(cfg, s, node_id));
  p.total = AlignUp64(off, 4096);
  return p;
}

}  // namespace

size_t SegmentSize(const SystemConfig& cfg, uint32_t node_id) {
  return static_cast<size_t>(MakePlan(cfg, node_id).total);  // fits: SegmentFitProblem checked
}

void BuildSegment(const SystemConfig& cfg, uint32_t node_id, void* mem, size_t size) {
  Plan p = MakePlan(cfg, node_id);
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

  uint64_t off = p.data;
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
    const uint32_t history = HistoryDepth(cfg, s, node_id);
    if (history) {
      d.history_depth = history;
      d.history_offset = off + DataBytes(s, 0);  // after the cell, its slots and safe value
    }
    off += DataBytes(s, history);
  }
  h->state.store(kInitializing, std::memory_order_relaxed);
}

namespace {

std::string HumanBytes(uint64_t b) {
  char buf[32];
  if (b >= (1ull << 30)) snprintf(buf, sizeof buf, "%.1f GB", static_cast<double>(b) / 1e9);
  else if (b >= (1ull << 20)) snprintf(buf, sizeof buf, "%.0f MB", static_cast<double>(b) / 1e6);
  else snprintf(buf, sizeof buf, "%llu kB", static_cast<unsigned long long>((b + 999) / 1000));
  return buf;
}

}  // namespace

std::string SegmentFitProblem(const SystemConfig& cfg, uint32_t node_id, const std::string& name) {
  const Plan p = MakePlan(cfg, node_id);
  const std::string node = cfg.nodes[node_id].name;
  // What makes it big: the signal with the most data (the usual cause, queue_depth x size).
  size_t biggest = 0;
  uint64_t biggest_bytes = 0;
  for (size_t i = 0; i < cfg.signals.size(); ++i) {
    const uint64_t b = DataBytes(cfg.signals[i], HistoryDepth(cfg, cfg.signals[i], node_id));
    if (b > biggest_bytes) biggest_bytes = b, biggest = i;
  }
  std::string need = "node '" + node + "' needs a " + HumanBytes(p.total) + " shared-memory segment";
  if (!cfg.signals.empty())
    need += " (largest signal '" + cfg.signals[biggest].name + "': " + HumanBytes(biggest_bytes) + ")";
  const char* fix = ": lower queue_depth, count or history, or ";
  if (p.total > SIZE_MAX / 2) return need + ", more than this system can map" + fix + "split the signals";
  // Re-adopting an existing segment of this size needs no new room in /dev/shm.
  bool adopt = false;
  int fd = platform::ShmOpenReadOnly(name.c_str());
  if (fd >= 0) {
    size_t size = 0;
    adopt = platform::FileSize(fd, &size) == 0 && size == p.total;
    platform::CloseFd(fd);
  }
  const uint64_t free_bytes = adopt ? UINT64_MAX : platform::ShmRoom();
  if (p.total > free_bytes)
    return need + ", but /dev/shm has " + HumanBytes(free_bytes) + " free" + fix +
           "enlarge /dev/shm (mount -o remount,size=...)";
  // ccommd holds the segment and, while it builds it, an image of the same size.
  const uint64_t memory = 2 * uint64_t{p.total};
  const uint64_t cgroup = platform::CgroupMemoryRoom();
  if (memory > cgroup)
    return need + " (twice that while starting), but the memory limit (cgroup memory.max) leaves " +
           HumanBytes(cgroup) + fix + "raise MemoryMax";
  const uint64_t as = platform::AddressSpaceRoom();
  if (memory > as)
    return need + " (twice that while starting), but RLIMIT_AS leaves " + HumanBytes(as) + fix +
           "raise LimitAS";
  return "";
}

int LockNode(const std::string& segment_name, int gid, int* holder_pid) {
  return platform::LockExclusive((segment_name + ".lock").c_str(), gid, holder_pid);
}

int CreateOrAdoptSegment(store::Segment* segment, const SystemConfig& cfg, uint32_t node_id,
                         const std::string& name, int gid, bool* adopted, std::string* error) {
  const size_t size = SegmentSize(cfg, node_id);
  std::unique_ptr<uint8_t[]> image(new (std::nothrow) uint8_t[size]);
  if (!image) {
    *error = "cannot allocate the " + HumanBytes(size) + " image of shared memory " + name;
    return -ENOMEM;
  }
  BuildSegment(cfg, node_id, image.get(), size);
  return segment->CreateOrAdopt(image.get(), size, name, gid, adopted, error);
}

}  // namespace ccomm
