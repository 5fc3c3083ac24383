// SPDX-License-Identifier: Apache-2.0
// Event rings: order, overrun accounting, backpressure, holes left by dead writers,
// and concurrent writers/readers (every event seen exactly once or counted lost).
#include "store/event_ring.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace ccomm {
namespace store {
namespace {

struct Ring {
  Ring(uint32_t depth, bool backpressure) {
    slot_bytes = sizeof(SlotHeader) + 8;
    mem.assign(sizeof(EventRing) + depth * slot_bytes + 64, 0);
    auto* base = reinterpret_cast<uint8_t*>(AlignUp(reinterpret_cast<uintptr_t>(mem.data()), 64));
    view.ring = new (base) EventRing();
    view.slots = base + sizeof(EventRing);
    view.slot_bytes = slot_bytes;
    view.value_bytes = 8;
    view.depth = depth;
    view.backpressure = backpressure;
  }
  std::vector<uint8_t> mem;
  uint32_t slot_bytes;
  RingView view;
};

TEST(EventRing, DeliversInOrderToEveryReader) {
  Ring r(8, false);
  RingCursor a, b;
  RingSubscribe(r.view, &a);
  RingSubscribe(r.view, &b);
  for (uint64_t i = 0; i < 5; ++i) ASSERT_EQ(RingWrite(r.view, &i, 0, 0, 0), StoreResult::kOk);
  SlotMeta m;
  for (RingCursor* c : {&a, &b}) {
    for (uint64_t i = 0; i < 5; ++i) {
      uint64_t v = 99;
      ASSERT_EQ(RingRead(r.view, c, &v, &m, 1), StoreResult::kOk);
      EXPECT_EQ(v, i);
      EXPECT_EQ(m.value_seq, i + 1);
    }
    uint64_t v;
    EXPECT_EQ(RingRead(r.view, c, &v, &m, 1), StoreResult::kEmpty);
    EXPECT_EQ(c->lost, 0u);
  }
}

TEST(EventRing, OverrunIsCountedNotSilent) {
  Ring r(4, false);
  RingCursor c;
  RingSubscribe(r.view, &c);
  for (uint64_t i = 0; i < 10; ++i) ASSERT_EQ(RingWrite(r.view, &i, 0, 0, 0), StoreResult::kOk);
  SlotMeta m;
  uint64_t v;
  std::vector<uint64_t> got;
  while (RingRead(r.view, &c, &v, &m, 1) == StoreResult::kOk) got.push_back(v);
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(got.front(), 6u);
  EXPECT_EQ(got.back(), 9u);
  EXPECT_EQ(c.lost, 6u);
  EXPECT_EQ(got.size() + c.lost, 10u);
}

TEST(EventRing, BackpressureRefusesInsteadOfDropping) {
  Ring r(4, true);
  for (uint64_t i = 0; i < 4; ++i) ASSERT_EQ(RingWrite(r.view, &i, 0, 0, 0), StoreResult::kOk);
  uint64_t x = 4;
  EXPECT_EQ(RingWrite(r.view, &x, 0, 0, 0), StoreResult::kFull);
  r.view.ring->fwd_cursor.store(2);  // the forwarder consumed two
  EXPECT_EQ(RingWrite(r.view, &x, 0, 0, 0), StoreResult::kOk);
  ++x;
  EXPECT_EQ(RingWrite(r.view, &x, 0, 0, 0), StoreResult::kOk);
  EXPECT_EQ(RingWrite(r.view, &x, 0, 0, 0), StoreResult::kFull);
}

TEST(EventRing, HoleFromDeadWriterIsSkippedAfterTimeout) {
  Ring r(8, false);
  RingCursor c;
  RingSubscribe(r.view, &c);
  uint64_t v = 1;
  ASSERT_EQ(RingWrite(r.view, &v, 0, 0, 0), StoreResult::kOk);
  // Dead writer: claims ticket 1 and never completes it.
  uint64_t t = r.view.ring->head.fetch_add(1);
  r.view.slot(t)->seq.store(2 * t + 1);
  v = 3;
  ASSERT_EQ(RingWrite(r.view, &v, 0, 0, 0), StoreResult::kOk);
  SlotMeta m;
  uint64_t out = 0;
  ASSERT_EQ(RingRead(r.view, &c, &out, &m, 1000), StoreResult::kOk);
  EXPECT_EQ(out, 1u);
  EXPECT_EQ(RingRead(r.view, &c, &out, &m, 2000), StoreResult::kPending);
  EXPECT_EQ(RingRead(r.view, &c, &out, &m, 2000 + kHoleTimeoutNs / 2), StoreResult::kPending);
  ASSERT_EQ(RingRead(r.view, &c, &out, &m, 2000 + kHoleTimeoutNs + 1), StoreResult::kOk);
  EXPECT_EQ(out, 3u);
  EXPECT_EQ(c.lost, 1u);
}

// A reader that has caught up does not look at `head` on every poll (it stays in the
// writers' cache); a hole behind it (a ticket never claimed in its slot) is still found
// once its last look is kHeadRecheckNs old, and skipped after the hole timeout.
TEST(EventRing, CaughtUpReaderFindsAnUnclaimedHoleAfterRecheck) {
  Ring r(8, false);
  RingCursor c;
  RingSubscribe(r.view, &c);
  SlotMeta m;
  uint64_t out = 0;
  const uint64_t t0 = 1000000;
  EXPECT_EQ(RingRead(r.view, &c, &out, &m, t0), StoreResult::kEmpty);  // looks at head once
  r.view.ring->head.fetch_add(1);  // a writer takes ticket 0 and dies before its slot
  uint64_t v = 7;
  ASSERT_EQ(RingWrite(r.view, &v, 0, 0, 0), StoreResult::kOk);  // ticket 1
  EXPECT_EQ(RingRead(r.view, &c, &out, &m, t0 + 1000), StoreResult::kEmpty);  // trusts its last look
  const uint64_t t1 = t0 + kHeadRecheckNs;
  EXPECT_EQ(RingRead(r.view, &c, &out, &m, t1), StoreResult::kPending);  // looked: a hole
  EXPECT_EQ(RingRead(r.view, &c, &out, &m, t1 + 1000), StoreResult::kPending);
  ASSERT_EQ(RingRead(r.view, &c, &out, &m, t1 + kHoleTimeoutNs + 1), StoreResult::kOk);
  EXPECT_EQ(out, 7u);
  EXPECT_EQ(c.lost, 1u);
  // now_ns == 0: no clock, so every poll looks at head (nothing is trusted).
  RingCursor d;
  RingSubscribe(r.view, &d);
  ASSERT_EQ(RingWrite(r.view, &v, 0, 0, 0), StoreResult::kOk);
  EXPECT_EQ(RingRead(r.view, &d, &out, &m, 0), StoreResult::kOk);
}

// Two writers, two readers; each reader must account for every event exactly once:
// received + lost == written, and per-writer values arrive in increasing order.
TEST(EventRing, ConcurrentWritersAndReadersAccountForEveryEvent) {
  Ring r(64, false);
  constexpr uint64_t kPerWriter = 20000;
  std::vector<RingCursor> cursors(2);
  for (auto& c : cursors) RingSubscribe(r.view, &c);
  std::atomic<int> writers_done{0};
  std::atomic<uint64_t> refused{0};
  std::vector<std::thread> th;
  for (uint64_t w = 0; w < 2; ++w) {
    th.emplace_back([&, w] {
      for (uint64_t i = 0; i < kPerWriter; ++i) {
        uint64_t v = (w << 32) | i;
        if (RingWrite(r.view, &v, 0, 0, 0) != StoreResult::kOk) refused++;
      }
      writers_done++;
    });
  }
  std::vector<uint64_t> received(2, 0);
  std::atomic<int> disorder{0};
  for (int k = 0; k < 2; ++k) {
    th.emplace_back([&, k] {
      uint64_t last[2] = {0, 0};
      bool any[2] = {false, false};
      SlotMeta m;
      uint64_t v;
      uint64_t empty_since = 0;
      for (;;) {
        uint64_t now = static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
        StoreResult res = RingRead(r.view, &cursors[k], &v, &m, now);
        if (res != StoreResult::kEmpty) empty_since = 0;
        if (res == StoreResult::kOk) {
          received[k]++;
          uint64_t w = v >> 32, i = v & 0xffffffffu;
          if (any[w] && i <= last[w]) disorder++;
          last[w] = i;
          any[w] = true;
        } else if (res == StoreResult::kEmpty && writers_done.load() == 2) {
          // Caught up with `head` as last seen; drained once that look is old enough.
          if (!empty_since) empty_since = now;
          if (now - empty_since > 2 * kHeadRecheckNs) break;
          std::this_thread::yield();
        } else {
          std::this_thread::yield();
        }
      }
    });
  }
  for (auto& t : th) t.join();
  // A refused write (kBusy) leaves a hole that readers skip and count as lost.
  RecordProperty("refused", static_cast<int>(refused.load()));
  EXPECT_EQ(disorder.load(), 0);
  for (int k = 0; k < 2; ++k) EXPECT_EQ(received[k] + cursors[k].lost, 2 * kPerWriter) << k;
}

}  // namespace
}  // namespace store
}  // namespace ccomm
