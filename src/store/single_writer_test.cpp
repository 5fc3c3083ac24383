// SPDX-License-Identifier: Apache-2.0
// StateWriteSingle (a state only ccommd writes): readers see what StateWrite would give
// them, never a torn value (run under TSan by scripts/test), a damaged copy is detected,
// and a writer killed mid-copy (then restarted on the same cell) loses nothing committed.
#include "store/state_slot.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "testing/run_until.h"

namespace ccomm {
namespace store {
namespace {

struct Cell {
  explicit Cell(uint32_t bytes) {
    const uint32_t slot_bytes = static_cast<uint32_t>(sizeof(SlotHeader) + AlignUp(bytes, 8));
    mem.assign(sizeof(StateCell) + kStateSlots * slot_bytes + 64, 0);
    uint8_t* base = reinterpret_cast<uint8_t*>(AlignUp(reinterpret_cast<uintptr_t>(mem.data()), 64));
    view.cell = new (base) StateCell();
    view.slots = base + sizeof(StateCell);
    view.slot_bytes = slot_bytes;
    view.value_bytes = bytes;
  }
  std::vector<uint8_t> mem;
  StateView view;
};

TEST(StateWriteSingle, ReadersSeeEveryValueWithItsMeta) {
  for (uint32_t bytes : {8u, 16u, 48u, 288u}) {  // inline copy, inline limit, slots only
    Cell c(bytes);
    std::vector<uint8_t> in(bytes), out(bytes);
    SlotMeta m;
    EXPECT_EQ(StateRead(c.view, out.data(), &m), StoreResult::kNever);
    for (uint64_t i = 1; i <= 10; ++i) {
      for (uint32_t k = 0; k < bytes; ++k) in[k] = static_cast<uint8_t>(i * 7 + k);
      StateWriteSingle(c.view, in.data(), SlotMeta{100 + i, 200 + i, 300 + i});
      ASSERT_EQ(StateRead(c.view, out.data(), &m), StoreResult::kOk) << bytes;
      EXPECT_EQ(out, in);
      EXPECT_EQ(m.value_seq, 100 + i);
      EXPECT_EQ(m.source_time_ns, 200 + i);
      EXPECT_EQ(m.local_time_ns, 300 + i);
      EXPECT_EQ(StateVersion(c.view), i);
    }
  }
}

TEST(StateWriteSingle, DamagedCopyIsDetectedNotReturned) {
  for (uint32_t bytes : {8u, 48u}) {
    Cell c(bytes);
    std::vector<uint8_t> in(bytes, 0x5a), out(bytes);
    SlotMeta m;
    StateWriteSingle(c.view, in.data(), SlotMeta{1, 2, 3});
    reinterpret_cast<uint8_t*>(c.view.slot(0) + 1)[bytes - 1] ^= 0x01;  // a stray client write
    reinterpret_cast<uint8_t*>(c.view.cell->inline_value)[0] ^= 0x01;
    EXPECT_EQ(StateRead(c.view, out.data(), &m), StoreResult::kCorrupt) << bytes;
    StateWriteSingle(c.view, in.data(), SlotMeta{2, 2, 3});
    ASSERT_EQ(StateRead(c.view, out.data(), &m), StoreResult::kOk);
    EXPECT_EQ(out, in);
  }
}

TEST(StateWriteSingle, WriterKilledMidCopyThenRestartedLosesNothing) {
  Cell c(8);
  double v = 1.0, out = 0;
  SlotMeta m;
  StateWriteSingle(c.view, &v, SlotMeta{1, 0, 0});
  // Killed mid-copy of ticket 1: its slot and the inline copy are left odd.
  c.view.slot(1)->seq.store(3);
  c.view.cell->inline_seq.store(3);
  ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);  // falls back to slot 0
  EXPECT_EQ(out, 1.0);
  EXPECT_EQ(m.value_seq, 1u);
  // The restarted writer carries on from `latest`.
  v = 2.0;
  StateWriteSingle(c.view, &v, SlotMeta{2, 0, 0});
  ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
  EXPECT_EQ(out, 2.0);
  EXPECT_EQ(m.value_seq, 2u);
}

// One writer puts N identical words per value; a torn read would mix two values.
class SingleWriterConcurrent : public testing::TestWithParam<int> {};
INSTANTIATE_TEST_SUITE_P(Sizes, SingleWriterConcurrent, testing::Values(1, 2, 36));

TEST_P(SingleWriterConcurrent, ReadersNeverSeeTornOrOlderValues) {
  constexpr int kMaxWords = 36;
  const int words = GetParam();
  Cell c(static_cast<uint32_t>(words * 8));
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> reads{0};
  std::atomic<int> torn{0}, backwards{0}, corrupt{0};
  std::vector<std::thread> threads;
  threads.emplace_back([&] {
    uint64_t vals[kMaxWords];
    for (uint64_t i = 1; !stop.load(std::memory_order_relaxed); ++i) {
      for (int k = 0; k < words; ++k) vals[k] = i;
      StateWriteSingle(c.view, vals, SlotMeta{i, i, i});
    }
  });
  for (int r = 0; r < 2; ++r) {
    threads.emplace_back([&] {
      uint64_t vals[kMaxWords];
      uint64_t last = 0;
      SlotMeta m;
      while (!stop.load(std::memory_order_relaxed)) {
        const StoreResult res = StateRead(c.view, vals, &m);
        if (res == StoreResult::kCorrupt) corrupt++;
        if (res != StoreResult::kOk) continue;
        reads++;
        for (int k = 0; k < words; ++k)
          if (vals[k] != m.value_seq) torn++;
        if (m.value_seq < last) backwards++;
        last = m.value_seq;
      }
    });
  }
  test_threads::SleepUntilEnough(std::chrono::milliseconds(300), [&] { return reads.load() > 100; });
  stop = true;
  for (auto& t : threads) t.join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_EQ(backwards.load(), 0);
  EXPECT_EQ(corrupt.load(), 0);
  EXPECT_GT(reads.load(), 100u);
}

}  // namespace
}  // namespace store
}  // namespace ccomm
