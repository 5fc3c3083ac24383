// SPDX-License-Identifier: Apache-2.0
// Multi-process stress: writer and reader processes hammer one segment; writers are
// killed with SIGKILL at random moments and replaced. Every value a reader accepts must
// be self-consistent (all words equal), state values must never go backwards for a
// reader, and when the storm is over the segment must still work for new clients.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <random>
#include <vector>

#include "common/platform.h"
#include "daemon/engine/segment_builder.h"
#include "store/reclaim.h"
#include "store/segment.h"
#include "testing/test_config.h"

namespace ccomm {
namespace store {
namespace {

constexpr int kWords = 16;

[[noreturn]] void Writer(const std::string& name, int id) {
  Segment s;
  if (s.Open(name) != 0) _exit(10);
  uint64_t v[kWords];
  uint64_t ev[kWords];
  for (uint64_t i = 1;; ++i) {
    for (auto& w : v) w = (i << 8) | static_cast<uint64_t>(id);
    StateWrite(s.state(0), v, 0, 0, platform::MonotonicNs());
    if ((i & 7) == 0) {
      for (auto& w : ev) w = (i << 8) | static_cast<uint64_t>(id);
      RingWrite(s.ring(1), ev, 0, 0, platform::MonotonicNs());
    }
  }
}

// Exit code: 0 ok, 1 torn state, 2 torn event, 3 per-writer order violated, 4 nothing read.
[[noreturn]] void Reader(const std::string& name, uint64_t until_ns) {
  Segment s;
  if (s.Open(name) != 0) _exit(10);
  RingCursor cur;
  RingSubscribe(s.ring(1), &cur);
  uint64_t v[kWords];
  SlotMeta m;
  uint64_t reads = 0, events = 0, last_seq = 0;
  while (platform::MonotonicNs() < until_ns) {
    if (StateRead(s.state(0), v, &m) == StoreResult::kOk) {
      for (int k = 1; k < kWords; ++k)
        if (v[k] != v[0]) _exit(1);
      if (m.value_seq < last_seq) _exit(3);  // a reader never sees an older copy after a newer one
      last_seq = m.value_seq;
      reads++;
    }
    StoreResult r = RingRead(s.ring(1), &cur, v, &m, platform::MonotonicNs());
    if (r == StoreResult::kOk) {
      for (int k = 1; k < kWords; ++k)
        if (v[k] != v[0]) _exit(2);
      events++;
    }
  }
  _exit(reads > 0 && events > 0 ? 0 : 4);
}

TEST(Stress, WritersKilledAtRandomNeverCorruptReaders) {
  setenv("CCOMM_SHM_PREFIX", testing::UniquePrefix("stress").c_str(), 1);
  auto st = testing::MakeSignal("state", ValueType::kInt64, kWords, SignalKind::kState, 0, {});
  auto ev = testing::MakeSignal("events", ValueType::kInt64, kWords, SignalKind::kEvent, 0, {});
  ev.queue_depth = 256;
  SystemConfig cfg = testing::TwoNodeConfig({st, ev});
  Segment seg;
  std::string err, name = SegmentName("a");
  bool adopted;
  ASSERT_EQ(CreateOrAdoptSegment(&seg, cfg, 0, name, -1, &adopted, &err), 0) << err;

  const double seconds = getenv("CCOMM_STRESS_SECONDS") ? atof(getenv("CCOMM_STRESS_SECONDS")) : 3.0;
  const uint64_t until = platform::MonotonicNs() + static_cast<uint64_t>(seconds * 1e9);
  std::vector<pid_t> readers;
  for (int r = 0; r < 3; ++r) {
    pid_t p = fork();
    if (p == 0) Reader(name, until);
    readers.push_back(p);
  }
  // What ccommd does: give back slots of dead writers, while everything runs.
  pid_t reclaimer = fork();
  if (reclaimer == 0) {
    Segment s;
    if (s.Open(name) != 0) _exit(10);
    std::vector<SlotSuspect> suspects(SlotCount(s));
    size_t total = 0;
    while (platform::MonotonicNs() < until + 500000000ull) {
      total += ReclaimAbandonedSlots(s, &suspects);
      usleep(20000);
    }
    _exit(total > 0 ? 0 : 5);  // with this many kills, some must have hit mid-write
  }
  std::mt19937 rng(12345);
  std::vector<pid_t> writers;
  int next_id = 0, kills = 0;
  for (int w = 0; w < 2; ++w) {
    pid_t p = fork();
    if (p == 0) Writer(name, next_id);
    next_id++;
    writers.push_back(p);
  }
  while (platform::MonotonicNs() < until) {
    usleep(std::uniform_int_distribution<int>(200, 5000)(rng));
    size_t victim = std::uniform_int_distribution<size_t>(0, writers.size() - 1)(rng);
    kill(writers[victim], SIGKILL);
    waitpid(writers[victim], nullptr, 0);
    kills++;
    pid_t p = fork();
    if (p == 0) Writer(name, next_id % 250);
    next_id++;
    writers[victim] = p;
  }
  for (pid_t p : writers) {
    kill(p, SIGKILL);
    waitpid(p, nullptr, 0);
  }
  for (pid_t p : readers) {
    int status = 0;
    waitpid(p, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "reader exit code (1 torn state, 2 torn event, 3 order, 4 idle)";
  }
  EXPECT_GT(kills, 10);  // fewer under TSan, where fork is slow
  int rstatus = 0;
  waitpid(reclaimer, &rstatus, 0);
  EXPECT_TRUE(WIFEXITED(rstatus) && WEXITSTATUS(rstatus) == 0) << "reclaimer found nothing to reclaim";
  // Afterwards the segment still works for a fresh writer and reader.
  uint64_t v[kWords], out[kWords];
  for (auto& w : v) w = 0xC0FFEE;
  ASSERT_EQ(StateWrite(seg.state(0), v, 0, 0, 1), StoreResult::kOk);
  SlotMeta m;
  ASSERT_EQ(StateRead(seg.state(0), out, &m), StoreResult::kOk);
  EXPECT_EQ(out[kWords - 1], 0xC0FFEEu);
  RingCursor c;
  RingSubscribe(seg.ring(1), &c);
  ASSERT_EQ(RingWrite(seg.ring(1), v, 0, 0, platform::MonotonicNs()), StoreResult::kOk);
  StoreResult r = StoreResult::kPending;
  for (int i = 0; i < 200 && r != StoreResult::kOk; ++i) {
    r = RingRead(seg.ring(1), &c, out, &m, platform::MonotonicNs());
    if (r != StoreResult::kOk) usleep(1000);
  }
  EXPECT_EQ(r, StoreResult::kOk);
  RecordProperty("writer_kills", kills);
  platform::ShmUnlink(name.c_str());
}

}  // namespace
}  // namespace store
}  // namespace ccomm
