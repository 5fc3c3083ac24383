// SPDX-License-Identifier: Apache-2.0
#include "daemon/segment_builder.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

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

// The smallest room left under memory.max of this process's cgroup and its ancestors
// (cgroup v2), or UINT64_MAX when none sets a limit (or there is no cgroup v2).
uint64_t CgroupMemoryRoom() {
  uint64_t room = UINT64_MAX;
  FILE* f = fopen("/proc/self/cgroup", "r");
  if (!f) return room;
  char line[512], path[512] = "";
  while (fgets(line, sizeof line, f))
    if (strncmp(line, "0::", 3) == 0) snprintf(path, sizeof path, "%s", line + 3);
  fclose(f);
  path[strcspn(path, "\n")] = '\0';
  std::string dir = path;
  for (;;) {
    unsigned long long max = 0, current = 0;
    const std::string base = "/sys/fs/cgroup" + dir;
    FILE* m = fopen((base + "/memory.max").c_str(), "r");
    FILE* c = fopen((base + "/memory.current").c_str(), "r");
    if (m && c && fscanf(m, "%llu", &max) == 1 && fscanf(c, "%llu", &current) == 1)
      room = std::min<uint64_t>(room, max > current ? max - current : 0);
    if (m) fclose(m);
    if (c) fclose(c);
    const size_t slash = dir.rfind('/');
    if (dir.empty() || slash == std::string::npos) break;
    dir.resize(slash);
  }
  return room;
}

// Address space left under RLIMIT_AS, or UINT64_MAX without a limit.
uint64_t AddressSpaceRoom() {
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return UINT64_MAX;
  unsigned long long pages = 0;
  if (FILE* f = fopen("/proc/self/statm", "r")) {
    if (fscanf(f, "%llu", &pages) != 1) pages = 0;
    fclose(f);
  }
  const uint64_t used = pages * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
  return rl.rlim_cur > used ? rl.rlim_cur - used : 0;
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
  int fd = shm_open(name.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd >= 0) {
    struct stat st;
    adopt = fstat(fd, &st) == 0 && static_cast<uint64_t>(st.st_size) == p.total;
    close(fd);
  }
  struct statvfs vfs;
  if (!adopt && statvfs("/dev/shm", &vfs) == 0) {
    const uint64_t free_bytes = uint64_t{vfs.f_bavail} * vfs.f_frsize;
    if (p.total > free_bytes)
      return need + ", but /dev/shm has " + HumanBytes(free_bytes) + " free" + fix +
             "enlarge /dev/shm (mount -o remount,size=...)";
  }
  // ccommd holds the segment and, while it builds it, an image of the same size.
  const uint64_t memory = 2 * uint64_t{p.total};
  const uint64_t cgroup = CgroupMemoryRoom();
  if (memory > cgroup)
    return need + " (twice that while starting), but the memory limit (cgroup memory.max) leaves " +
           HumanBytes(cgroup) + fix + "raise MemoryMax";
  const uint64_t as = AddressSpaceRoom();
  if (memory > as)
    return need + " (twice that while starting), but RLIMIT_AS leaves " + HumanBytes(as) + fix +
           "raise LimitAS";
  return "";
}

int LockNode(const std::string& segment_name, int gid, int* holder_pid) {
  *holder_pid = 0;
  const std::string name = segment_name + ".lock";
  int fd = shm_open(name.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0660);
  if (fd < 0) return -errno;
  // The first ccommd creates it: umask must not narrow it, and the group shares it.
  struct stat st;
  if (fstat(fd, &st) == 0 && st.st_uid == geteuid()) {
    if (fchmod(fd, 0660) != 0) { /* best effort: the lock works without */ }
    if (gid >= 0 && fchown(fd, static_cast<uid_t>(-1), static_cast<gid_t>(gid)) != 0) { /* idem */ }
  }
  struct flock lk;
  memset(&lk, 0, sizeof lk);
  lk.l_type = F_WRLCK;
  lk.l_whence = SEEK_SET;
  if (fcntl(fd, F_SETLK, &lk) == 0) return fd;
  const int e = errno;
  if (e == EAGAIN || e == EACCES) {
    memset(&lk, 0, sizeof lk);
    lk.l_type = F_WRLCK;
    lk.l_whence = SEEK_SET;
    if (fcntl(fd, F_GETLK, &lk) == 0 && lk.l_type != F_UNLCK) *holder_pid = lk.l_pid;
    close(fd);
    return -EBUSY;
  }
  close(fd);
  return -e;
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
