// SPDX-License-Identifier: Apache-2.0
#include "daemon/segment_builder.h"

#include <stdio.h>
#include <string.h>

#include <new>
#include <vector>

#include "common/platform.h"

namespace ccomm {

using namespace store;  // the layout types this file fills in

namespace {

struct Plan {
  size_t directory, node_names, signal_stats, peer_stats, dirty, data, total;
};

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

size_t DataBytes(const SignalConfig& s, uint32_t history_depth) {
  size_t slots = s.kind == SignalKind::kEvent ? s.queue_depth : kStateSlots;
  size_t head = s.kind == SignalKind::kEvent ? sizeof(EventRing) : sizeof(StateCell);
  size_t safe = s.has_safe_value ? AlignUp(s.value_bytes(), 8) : 0;
  size_t history = history_depth ? sizeof(EventRing) + history_depth * SlotBytes(s) : 0;
  return AlignUp(head + slots * SlotBytes(s) + safe, kCacheLine) + history;
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
  size_t off = p.data;
  for (const auto& s : cfg.signals) off += DataBytes(s, HistoryDepth(cfg, s, node_id));
  p.total = AlignUp(off, 4096);
  return p;
}

}  // namespace

size_t SegmentSize(const SystemConfig& cfg, uint32_t node_id) { return MakePlan(cfg, node_id).total; }

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
    const uint32_t history = HistoryDepth(cfg, s, node_id);
    if (history) {
      d.history_depth = history;
      d.history_offset = off + DataBytes(s, 0);  // after the cell, its slots and safe value
    }
    off += DataBytes(s, history);
  }
  h->state.store(kInitializing, std::memory_order_relaxed);
}

int RunningDaemonOf(const std::string& name) {
  store::Segment existing;
  if (existing.Open(name) != 0) return 0;  // none, or another layout: CreateOrAdopt decides
  const store::SegmentHeader* h = existing.header();
  const int pid = h->daemon_pid.load(std::memory_order_acquire);
  if (pid <= 0 || pid == static_cast<int>(platform::ProcessId())) return 0;
  const uint64_t first = h->daemon_heartbeat_ns.load(std::memory_order_acquire);
  for (int i = 0; i < 20; ++i) {  // its supervision tick stamps every 10 ms
    platform::SleepNs(5000000);
    if (h->daemon_heartbeat_ns.load(std::memory_order_acquire) != first) return pid;
  }
  return 0;
}

int CreateOrAdoptSegment(store::Segment* segment, const SystemConfig& cfg, uint32_t node_id,
                         const std::string& name, int gid, bool* adopted, std::string* error) {
  const size_t size = SegmentSize(cfg, node_id);
  std::vector<uint8_t> image(size);
  BuildSegment(cfg, node_id, image.data(), size);
  return segment->CreateOrAdopt(image.data(), size, name, gid, adopted, error);
}

}  // namespace ccomm
