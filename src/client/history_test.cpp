// SPDX-License-Identifier: Apache-2.0
// The history tap (ccomm_history_*): every value ccommd appends to a received state's
// history ring reaches a reader in order, or is counted as overrun; never silently lost.
// The appends are made as ccommd's receive path makes them (Daemon::AppendHistory).
#include <gtest/gtest.h>
#include <stdlib.h>

#include <array>
#include <atomic>
#include <thread>

#include "ccomm/ccomm.h"
#include "ccomm/ccomm.hpp"
#include "common/platform.h"
#include "daemon/engine/segment_builder.h"
#include "store/segment.h"
#include "testing/test_config.h"

namespace ccomm {
namespace {

using testing::MakeSignal;

constexpr uint32_t kDepth = 8;

class HistoryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("CCOMM_SHM_PREFIX", testing::UniquePrefix("history").c_str(), 1);
    std::vector<SignalConfig> signals = testing::PosAndSetpoint(2);
    signals.push_back(MakeSignal("estop", ValueType::kBool, 1, SignalKind::kEvent, 1, {0}));
    cfg_ = testing::TwoNodeConfig(signals);
    cfg_.nodes[0].history = kDepth;
    std::string err;
    bool adopted;
    ASSERT_EQ(CreateOrAdoptSegment(&seg_, cfg_, 0, store::SegmentName("a"), -1, &adopted, &err), 0) << err;
    seg_.header()->state.store(store::kReady);
    ASSERT_EQ(ccomm_open("a", 0, &c_), 0);
    sp_ = ccomm_find(c_, "sp");
  }
  void TearDown() override {
    ccomm_close(c_);
    platform::ShmUnlink(store::SegmentName("a").c_str());
  }
  // What ccommd stores for the value numbered `seq` (both elements derive from it).
  void Append(uint64_t seq) {
    const double v[2] = {static_cast<double>(seq), -static_cast<double>(seq)};
    ASSERT_EQ(store::RingWrite(seg_.history(1), v, seq, 1000 + seq, 2000 + seq), store::StoreResult::kOk);
  }
  SystemConfig cfg_;
  store::Segment seg_;
  ccomm_client* c_ = nullptr;
  ccomm_signal sp_ = -1;
};

TEST_F(HistoryTest, OnlyReceivedStatesHaveAHistory) {
  EXPECT_EQ(ccomm_history_depth(c_, sp_), static_cast<int>(kDepth));
  EXPECT_EQ(ccomm_history_depth(c_, ccomm_find(c_, "pos")), 0);    // produced here
  EXPECT_EQ(ccomm_history_depth(c_, ccomm_find(c_, "estop")), 0);  // events have their own ring
  EXPECT_EQ(ccomm_history_depth(c_, 99), CCOMM_E_INVAL);
  ccomm_history_cursor cur;
  EXPECT_EQ(ccomm_history_start(c_, ccomm_find(c_, "pos"), 0, &cur), CCOMM_E_NOENT);
  double v[2];
  EXPECT_EQ(ccomm_history_read(c_, ccomm_find(c_, "pos"), &cur, v, sizeof v, nullptr), CCOMM_E_NOENT);
  ASSERT_EQ(ccomm_history_start(c_, sp_, 0, &cur), 0);
  EXPECT_EQ(ccomm_history_read(c_, sp_, &cur, v, 8, nullptr), CCOMM_E_TYPE);

  // The rings take segment space on the node that asks for them only.
  SystemConfig plain = cfg_, deep = cfg_;
  plain.nodes[0].history = 0;
  deep.nodes[0].history = 4096;
  EXPECT_LT(SegmentSize(plain, 0), SegmentSize(deep, 0));
  EXPECT_EQ(SegmentSize(plain, 1), SegmentSize(deep, 1));
}

TEST_F(HistoryTest, ReadsEveryValueInOrderThenEmpty) {
  ccomm_history_cursor cur;
  ASSERT_EQ(ccomm_history_start(c_, sp_, 0, &cur), 0);
  double v[2];
  ccomm_history_info info;
  EXPECT_EQ(ccomm_history_read(c_, sp_, &cur, v, sizeof v, &info), CCOMM_EMPTY);
  for (uint64_t s = 1; s <= 5; ++s) Append(s);
  for (uint64_t s = 1; s <= 5; ++s) {
    ASSERT_EQ(ccomm_history_read(c_, sp_, &cur, v, sizeof v, &info), CCOMM_FRESH);
    EXPECT_EQ(info.seq, s);
    EXPECT_EQ(v[0], static_cast<double>(s));
    EXPECT_EQ(v[1], -static_cast<double>(s));
    EXPECT_EQ(info.source_time_ns, 1000 + s);
    EXPECT_EQ(info.receive_time_ns, 2000 + s);
    EXPECT_EQ(info.overrun, 0u);
  }
  EXPECT_EQ(ccomm_history_read(c_, sp_, &cur, v, sizeof v, &info), CCOMM_EMPTY);
  // Independent cursors started back in the history see the values kept again.
  ccomm_history_cursor again;
  ASSERT_EQ(ccomm_history_start(c_, sp_, 1000, &again), 0);
  ASSERT_EQ(ccomm_history_read(c_, sp_, &again, v, sizeof v, &info), CCOMM_FRESH);
  EXPECT_EQ(info.seq, 1u);
  ASSERT_EQ(ccomm_history_start(c_, sp_, 1, &again), 0);
  ASSERT_EQ(ccomm_history_read(c_, sp_, &again, v, sizeof v, &info), CCOMM_FRESH);
  EXPECT_EQ(info.seq, 5u);
  EXPECT_EQ(ccomm_history_read(c_, sp_, &again, v, sizeof v, &info), CCOMM_EMPTY);
}

TEST_F(HistoryTest, FallingBehindIsCountedExactly) {
  ccomm_history_cursor cur;
  ASSERT_EQ(ccomm_history_start(c_, sp_, 0, &cur), 0);
  const uint64_t total = 3 * kDepth + 5;
  for (uint64_t s = 1; s <= total; ++s) Append(s);
  double v[2];
  ccomm_history_info info;
  uint64_t got = 0, expect = total - kDepth + 1;
  while (ccomm_history_read(c_, sp_, &cur, v, sizeof v, &info) == CCOMM_FRESH) {
    EXPECT_EQ(info.seq, expect);  // the newest kDepth values, in order
    EXPECT_EQ(v[0], static_cast<double>(expect));
    ++expect;
    ++got;
  }
  EXPECT_EQ(got, kDepth);
  EXPECT_EQ(cur.overrun, total - kDepth);
  EXPECT_EQ(info.overrun, total - kDepth);
  EXPECT_EQ(got + cur.overrun, total);  // every value read or counted
}

// ccommd's receive thread appends while a recorder reads (TSan checks the protocol): each
// value arrives intact and in order, and read + overrun = written at the end.
TEST_F(HistoryTest, ConcurrentAppendAndReadLoseNothingUncounted) {
  ccomm_history_cursor cur;
  ASSERT_EQ(ccomm_history_start(c_, sp_, 0, &cur), 0);
  constexpr uint64_t kValues = 200000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (uint64_t s = 1; s <= kValues; ++s) Append(s);
    done.store(true, std::memory_order_release);
  });
  uint64_t got = 0, last = 0;
  bool ordered = true, intact = true;
  double v[2];
  ccomm_history_info info;
  for (;;) {
    const bool finished = done.load(std::memory_order_acquire);
    int r;
    while ((r = ccomm_history_read(c_, sp_, &cur, v, sizeof v, &info)) == CCOMM_FRESH) {
      ordered &= info.seq > last;
      intact &= v[0] == static_cast<double>(info.seq) && v[1] == -v[0];
      last = info.seq;
      ++got;
    }
    ASSERT_EQ(r, CCOMM_EMPTY);
    if (finished) break;
  }
  writer.join();
  EXPECT_TRUE(ordered);
  EXPECT_TRUE(intact);
  EXPECT_EQ(last, kValues);
  EXPECT_EQ(got + cur.overrun, kValues);
}

TEST_F(HistoryTest, CppHistoryReadsWhatTheCApiReads) {
  ccomm::Client client("a");
  ASSERT_TRUE(client.ok());
  auto sp = client.signal<std::array<double, 2>>("sp");
  ASSERT_TRUE(sp.valid());
  auto none = client.signal<double>("pos").history();
  EXPECT_EQ(none.status(), CCOMM_E_NOENT);  // produced here: no history
  EXPECT_EQ(none.read().status, CCOMM_E_NOENT);
  auto h = sp.history(0);
  ASSERT_EQ(h.status(), 0);
  EXPECT_EQ(h.depth(), static_cast<int>(kDepth));
  EXPECT_TRUE(h.read().empty());
  for (uint64_t s = 1; s <= kDepth + 3; ++s) Append(s);
  uint64_t first = 0, n = 0;
  for (auto r = h.read(); !r.empty(); r = h.read()) {
    ASSERT_FALSE(r.error());
    if (!first) first = r.info.seq;
    EXPECT_EQ(r.value[1], -static_cast<double>(r.info.seq));
    ++n;
  }
  EXPECT_EQ(n, kDepth);
  EXPECT_EQ(first, 4u);
  EXPECT_EQ(h.overrun(), 3u);
}

}  // namespace
}  // namespace ccomm
