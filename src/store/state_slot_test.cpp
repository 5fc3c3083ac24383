// SPDX-License-Identifier: Apache-2.0
// State slots: single-thread semantics, a writer that "dies" mid-write, and a
// concurrent torn-read check (run under TSan by scripts/test).
#include "store/state_slot.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <thread>
#include <vector>

#include "testing/run_until.h"

namespace ccomm {
namespace store {
namespace {

struct Cell {
  explicit Cell(uint32_t bytes) : value_bytes(bytes) {
    slot_bytes = sizeof(SlotHeader) + AlignUp(bytes, 8);
    mem.assign(sizeof(StateCell) + kStateSlots * slot_bytes + 64, 0);
    base = reinterpret_cast<uint8_t*>(AlignUp(reinterpret_cast<uintptr_t>(mem.data()), 64));
    view.cell = new (base) StateCell();
    view.slots = base + sizeof(StateCell);
    view.slot_bytes = slot_bytes;
    view.value_bytes = bytes;
  }
  std::vector<uint8_t> mem;
  uint8_t* base;
  uint32_t value_bytes, slot_bytes;
  StateView view;
};

TEST(StateSlot, NeverThenLastValueWins) {
  Cell c(8);
  double v = 0;
  SlotMeta m;
  EXPECT_EQ(StateRead(c.view, &v, &m), StoreResult::kNever);
  for (int i = 1; i <= 10; ++i) {
    double w = i * 1.5;
    uint64_t seq = 0;
    ASSERT_EQ(StateWrite(c.view, &w, 0, 100 + i, 200 + i, &seq), StoreResult::kOk);
    EXPECT_EQ(seq, static_cast<uint64_t>(i));
  }
  ASSERT_EQ(StateRead(c.view, &v, &m), StoreResult::kOk);
  EXPECT_EQ(v, 15.0);
  EXPECT_EQ(m.value_seq, 10u);
  EXPECT_EQ(m.source_time_ns, 110u);
  EXPECT_EQ(m.local_time_ns, 210u);
}

TEST(StateSlot, ExplicitSequenceNumbersAreKept) {
  Cell c(4);
  // The store's word copies see only value_bytes (4), but GCC 12 at -O3 cannot prove
  // that for a stack float inlined into them (-Warray-bounds): give it a whole word.
  union {
    float f;
    uint64_t word;
  } in = {2.5f};
  ASSERT_EQ(StateWrite(c.view, &in, 777, 1, 2), StoreResult::kOk);
  SlotMeta m;
  union {  // the same for the read (its 8-byte fast path is inlined too)
    float f;
    uint64_t word;
  } out = {0.0f};
  ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
  EXPECT_EQ(out.f, 2.5f);
  EXPECT_EQ(m.value_seq, 777u);
}

TEST(StateSlot, OddSizedArraysRoundTrip) {
  Cell c(13);
  uint8_t in[13], out[13] = {};
  for (int i = 0; i < 13; ++i) in[i] = static_cast<uint8_t>(i * 7 + 1);
  ASSERT_EQ(StateWrite(c.view, in, 0, 0, 0), StoreResult::kOk);
  SlotMeta m;
  ASSERT_EQ(StateRead(c.view, out, &m), StoreResult::kOk);
  EXPECT_EQ(0, memcmp(in, out, 13));
}

// A writer killed between claiming a slot and completing it leaves the slot odd.
// Readers keep seeing the last complete value; later writers go around the hole.
TEST(StateSlot, DeadWriterNeitherCorruptsNorStalls) {
  Cell c(8);
  double v = 1.0;
  ASSERT_EQ(StateWrite(c.view, &v, 0, 0, 0), StoreResult::kOk);
  // Simulate the dead writer: claim ticket 1's slot by hand and scribble half a value.
  uint64_t t = c.view.cell->next_ticket.fetch_add(1);
  SlotHeader* h = c.view.slot(t);
  h->seq.store(2 * t + 1);
  memset(reinterpret_cast<uint8_t*>(h) + sizeof(SlotHeader), 0xAB, 4);
  double out = 0;
  SlotMeta m;
  ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
  EXPECT_EQ(out, 1.0);
  for (int i = 0; i < 50; ++i) {
    double w = 100.0 + i;
    ASSERT_EQ(StateWrite(c.view, &w, 0, 0, 0), StoreResult::kOk) << i;
    ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
    EXPECT_EQ(out, w);
  }
}

// Two slots held by dead writers still leave room to write and read.
TEST(StateSlot, TwoDeadWritersStillWork) {
  Cell c(8);
  for (int k = 0; k < 2; ++k) {
    uint64_t t = c.view.cell->next_ticket.fetch_add(1);
    c.view.slot(t)->seq.store(2 * t + 1);
  }
  double out = 0;
  SlotMeta m;
  for (int i = 0; i < 20; ++i) {
    double w = i;
    ASSERT_EQ(StateWrite(c.view, &w, 0, 0, 0), StoreResult::kOk);
    ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
    EXPECT_EQ(out, w);
  }
}

// Small values are also in the cell's first line, for ticket `latest - 1` only.
TEST(StateSlot, SmallValuesAreCopiedInline) {
  Cell small(16), big(24);
  uint64_t a[3] = {1, 2, 3};
  ASSERT_EQ(StateWrite(small.view, a, 0, 5, 6), StoreResult::kOk);
  ASSERT_EQ(StateWrite(big.view, a, 0, 5, 6), StoreResult::kOk);
  EXPECT_EQ(small.view.cell->inline_seq.load(), 2u);  // ticket 0, complete
  EXPECT_EQ(small.view.cell->inline_claim.seq.load(), 2u);  // and released
  EXPECT_EQ(small.view.cell->inline_value[1].load(), 2u);
  EXPECT_EQ(small.view.cell->inline_meta[2].load(), 6u);  // local time
  EXPECT_EQ(big.view.cell->inline_seq.load(), 0u);  // too big: slots only
  // A reader takes the inline copy: make the slot unreadable and read anyway.
  small.view.slot(0)->seq.store(99);
  uint64_t out[2] = {};
  SlotMeta m;
  ASSERT_EQ(StateRead(small.view, out, &m), StoreResult::kOk);
  EXPECT_EQ(out[1], 2u);
  EXPECT_EQ(m.value_seq, 1u);
}

// A writer killed while filling the inline copy leaves it odd: readers use the slots,
// later writers skip the inline copy, and nothing is lost or torn.
TEST(StateSlot, DeadInlineWriterFallsBackToSlots) {
  Cell c(8);
  double v = 1.0;
  ASSERT_EQ(StateWrite(c.view, &v, 0, 0, 0), StoreResult::kOk);
  uint64_t t = c.view.cell->next_ticket.fetch_add(1);  // the dead writer's ticket
  c.view.cell->inline_claim.seq.store(2 * t + 1);
  c.view.cell->inline_seq.store(2 * t + 1);
  c.view.cell->inline_value[0].store(0xABABABABABABABABull);
  double out = 0;
  SlotMeta m;
  ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
  EXPECT_EQ(out, 1.0);
  for (int i = 0; i < 20; ++i) {
    double w = 10.0 + i;
    ASSERT_EQ(StateWrite(c.view, &w, 0, 0, 0), StoreResult::kOk);
    ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
    EXPECT_EQ(out, w);
  }
  EXPECT_EQ(c.view.cell->inline_claim.seq.load(), 2 * t + 1);  // untouched until reclaimed
  EXPECT_EQ(c.view.cell->inline_seq.load(), 2 * t + 1);
  c.view.cell->inline_claim.seq.store(0);                      // what ccommd's reclaim does
  double w = 99.0;
  ASSERT_EQ(StateWrite(c.view, &w, 0, 0, 0), StoreResult::kOk);
  EXPECT_EQ(c.view.cell->inline_seq.load() % 2, 0u);
  EXPECT_GT(c.view.cell->inline_seq.load(), 2 * t + 2);
  ASSERT_EQ(StateRead(c.view, &out, &m), StoreResult::kOk);
  EXPECT_EQ(out, 99.0);
}

// Writers put N identical words per value; a torn read would mix two values.
// 2 words go through the inline copy, 36 through the slots only.
class StateSlotConcurrent : public testing::TestWithParam<int> {};
INSTANTIATE_TEST_SUITE_P(Sizes, StateSlotConcurrent, testing::Values(2, 36));

TEST_P(StateSlotConcurrent, ReadersNeverSeeTornValues) {
  constexpr int kMaxWords = 36;
  const int kWords = GetParam();
  Cell c(kWords * 8);
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> reads{0}, busy{0};
  std::vector<std::thread> threads;
  for (int w = 0; w < 2; ++w) {
    threads.emplace_back([&, w] {
      uint64_t vals[kMaxWords];
      for (uint64_t i = 1; !stop.load(std::memory_order_relaxed); ++i) {
        for (int k = 0; k < kWords; ++k) vals[k] = (i << 8) | static_cast<uint64_t>(w);
        StateWrite(c.view, vals, 0, 0, 0);
      }
    });
  }
  std::atomic<int> torn{0};
  for (int r = 0; r < 2; ++r) {
    threads.emplace_back([&] {
      uint64_t vals[kMaxWords];
      SlotMeta m;
      while (!stop.load(std::memory_order_relaxed)) {
        StoreResult res = StateRead(c.view, vals, &m);
        if (res == StoreResult::kBusy) { busy++; continue; }
        if (res != StoreResult::kOk) continue;
        reads++;
        for (int k = 1; k < kWords; ++k)
          if (vals[k] != vals[0]) torn++;
      }
    });
  }
  test_threads::SleepUntilEnough(std::chrono::milliseconds(300), [&] { return reads.load() > 100; });
  stop = true;
  for (auto& t : threads) t.join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_GT(reads.load(), 100u);
}

// One application writing (the ticketed protocol), readers polling: a reader never gets
// an older value than its last read. The inline copy can be newer than `latest`; a read
// that finds it being rewritten must not fall back to the slot of a `latest` it loaded
// before the rewrite began (it did once: a backwards read for 16-byte values).
class StateSlotOneWriter : public testing::TestWithParam<int> {};
INSTANTIATE_TEST_SUITE_P(Sizes, StateSlotOneWriter, testing::Values(1, 2));

TEST_P(StateSlotOneWriter, ReadersNeverGoBackwards) {
  const int kWords = GetParam();
  Cell c(kWords * 8);
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> reads{0};
  std::atomic<int> backwards{0};
  std::vector<std::thread> threads;
  threads.emplace_back([&] {
    uint64_t vals[2];
    for (uint64_t i = 1; !stop.load(std::memory_order_relaxed); ++i) {
      vals[0] = vals[1] = i;
      StateWrite(c.view, vals, i, 0, 0);
    }
  });
  for (int r = 0; r < 2; ++r) {
    threads.emplace_back([&] {
      uint64_t vals[2], last = 0;
      SlotMeta m;
      while (!stop.load(std::memory_order_relaxed)) {
        if (StateRead(c.view, vals, &m) != StoreResult::kOk) continue;
        reads++;
        if (m.value_seq < last) backwards++;
        last = m.value_seq;
      }
    });
  }
  test_threads::SleepUntilEnough(std::chrono::milliseconds(300), [&] { return reads.load() > 100; });
  stop = true;
  for (auto& t : threads) t.join();
  EXPECT_EQ(backwards.load(), 0);
  EXPECT_GT(reads.load(), 100u);
}

}  // namespace
}  // namespace store
}  // namespace ccomm

namespace ccomm {
namespace store {
namespace {

// A stray write over a complete copy (sequence word untouched) is detected by the
// copy's check: the reader gets kCorrupt, never the damaged value.
TEST(StateSlotCheck, DamagedCopyIsDetectedNotReturned) {
  for (uint32_t bytes : {8u, 16u, 48u}) {  // inline copy, inline limit, slot only
    std::vector<uint8_t> mem(sizeof(StateCell) + kStateSlots * 128 + 64, 0);
    auto* base = reinterpret_cast<uint8_t*>(AlignUp(reinterpret_cast<uintptr_t>(mem.data()), 64));
    StateView v;
    v.cell = new (base) StateCell();
    v.slots = base + sizeof(StateCell);
    v.slot_bytes = 128;
    v.value_bytes = bytes;
    std::vector<uint8_t> in(bytes, 0x5a), out(bytes);
    ASSERT_EQ(StateWrite(v, in.data(), 0, 1, 2), StoreResult::kOk);
    SlotMeta m;
    ASSERT_EQ(StateRead(v, out.data(), &m), StoreResult::kOk);
    // Damage the value in every copy a reader could take (slot and inline line).
    reinterpret_cast<uint8_t*>(v.slot(0) + 1)[bytes - 1] ^= 0x01;
    reinterpret_cast<uint8_t*>(v.cell->inline_value)[bytes <= kInlineValueBytes ? bytes - 1 : 0] ^= 0x01;
    EXPECT_EQ(StateRead(v, out.data(), &m), StoreResult::kCorrupt) << bytes << "-byte value";
    // The next genuine write is read normally again.
    ASSERT_EQ(StateWrite(v, in.data(), 0, 3, 4), StoreResult::kOk);
    ASSERT_EQ(StateRead(v, out.data(), &m), StoreResult::kOk);
    EXPECT_EQ(out, in);
  }
}

}  // namespace
}  // namespace store
}  // namespace ccomm
