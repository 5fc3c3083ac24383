// SPDX-License-Identifier: Apache-2.0
// ccomm_view_production_age (C) and SystemView::production_age (C++): a value's age since
// its producer wrote it, on the boards' common time base, with its error bound, and never
// a number presented as exact when a clock behind it is not synced (issue 29). The view
// is written here as ccommd would from the node summaries (store/view.h).
#include "ccomm/ccomm.h"
#include "ccomm/ccomm.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdlib>

#include <string>

#include "common/platform.h"
#include "daemon/engine/segment_builder.h"
#include "store/segment.h"
#include "store/view.h"
#include "testing/test_config.h"

namespace ccomm {
namespace {

using testing::MakeSignal;

constexpr uint32_t kSynced = 2, kSyncing = 1;
constexpr uint64_t kNoBound = 0xFFFFFFFFu;  // wire::kSummaryNoClockError
constexpr int64_t kMs = 1000000;

class ProductionAgeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("CCOMM_SHM_PREFIX", testing::UniquePrefix("page").c_str(), 1);
    // Node a (0, this one) produces "pos"; node b (1) produces "sp", which a consumes.
    cfg_ = testing::TwoNodeConfig(testing::PosAndSetpoint());
    std::string err;
    bool adopted;
    ASSERT_EQ(CreateOrAdoptSegment(&seg_, cfg_, 0, store::SegmentName("a"), -1, &adopted, &err), 0) << err;
    ASSERT_EQ(view_.Create(store::View::NameFor("a"), 2, 2, 0, 1000, -1, &err), 0) << err;
    view_.mutable_header()->state.store(store::kViewReady, std::memory_order_release);
    ASSERT_EQ(ccomm_open("a", 0, &c_), 0);
    ASSERT_EQ(ccomm_view_open(c_, &v_), 0);
  }
  void TearDown() override {
    ccomm_view_close(v_);
    ccomm_close(c_);
    platform::ShmUnlink(store::View::NameFor("a").c_str());
    platform::ShmUnlink(store::SegmentName("a").c_str());
  }
  // Node `n`'s record as its latest summary would leave it (heard now, 10 s timeout).
  void SetClock(uint32_t n, uint32_t state, uint64_t error_ns, int64_t offset_ns, bool heard = true) {
    view_.BeginWrite(n);
    view_.SetNodeWord(n, store::kVwLastRxNs, heard ? platform::MonotonicNs() : 0);
    view_.SetNodeWord(n, store::kVwTimeoutNs, 10000 * kMs);
    view_.SetNodeWord(n, store::kVwClockState, state);
    view_.SetNodeWord(n, store::kVwClockErrorNs, error_ns);
    view_.SetNodeWord(n, store::kVwClockOffsetNs, static_cast<uint64_t>(offset_ns));
    view_.EndWrite(n);
  }
  ccomm_production_age Age(ccomm_signal s, const ccomm_info& info) {
    ccomm_production_age a;
    EXPECT_EQ(ccomm_view_production_age(v_, s, &info, &a), 0);
    return a;
  }
  static void ExpectUnknown(const ccomm_production_age& a, int code) {
    EXPECT_EQ(a.code, code) << ccomm_production_age_name(a.code);
    EXPECT_EQ(a.known, 0);
    EXPECT_EQ(a.age_ns, -1);
    EXPECT_EQ(a.error_ns, -1);
    EXPECT_EQ(a.production_time_ns, -1);
  }

  SystemConfig cfg_;
  store::Segment seg_;
  store::View view_;
  ccomm_client* c_ = nullptr;
  ccomm_view* v_ = nullptr;
};

TEST_F(ProductionAgeTest, KnownOnlyWhenBothClocksAreSynced) {
  const ccomm_signal sp = ccomm_find(c_, "sp");
  ASSERT_GE(sp, 0);
  // Board b's monotonic clock started 1000 s after ours: its offset to the common time
  // base is 1000 s smaller, its stamps 1000 s smaller. Its value was written 40 ms ago.
  const int64_t b_shift = 1000000 * kMs;
  ccomm_info info{};
  info.seq = 3;
  info.age_ns = 1 * kMs;  // arrived 1 ms ago: the local age says nothing of the 40 ms
  info.source_time_ns = platform::MonotonicNs() - 40 * kMs - b_shift;
  const int64_t b_offset = platform::RealtimeOffsetNs() + b_shift;

  ccomm_info never{};
  ExpectUnknown(Age(sp, never), CCOMM_PAGE_NEVER);
  SetClock(0, 0, kNoBound, platform::RealtimeOffsetNs());  // this board: no ptp4l
  SetClock(1, kSynced, 3000, b_offset);
  ExpectUnknown(Age(sp, info), CCOMM_PAGE_LOCAL_UNSYNCED);
  SetClock(0, kSynced, 2000, platform::RealtimeOffsetNs());
  SetClock(1, kSynced, 3000, b_offset, /*heard=*/false);
  ExpectUnknown(Age(sp, info), CCOMM_PAGE_NO_SUMMARY);
  SetClock(1, kSyncing, kNoBound, b_offset);
  ExpectUnknown(Age(sp, info), CCOMM_PAGE_PRODUCER_UNSYNCED);
  SetClock(1, kSynced, 3000, b_offset);
  const ccomm_production_age a = Age(sp, info);
  EXPECT_EQ(a.code, CCOMM_PAGE_SYNCED);
  EXPECT_EQ(a.known, 1);
  EXPECT_EQ(a.error_ns, 2000 + 3000 + 2000);  // both bounds, and reading the two offsets
  EXPECT_GE(a.age_ns, 40 * kMs - a.error_ns);
  EXPECT_LT(a.age_ns, 40 * kMs + 5000 * kMs);  // a loaded machine may pause the test for seconds
  // The write on the common time base: the producer's stamp moved by its own offset, exactly.
  EXPECT_EQ(a.production_time_ns, static_cast<int64_t>(info.source_time_ns) + b_offset);
  // A lost clock is no clock: unknown again, not the last good number.
  SetClock(1, 3, kNoBound, b_offset);
  ExpectUnknown(Age(sp, info), CCOMM_PAGE_PRODUCER_UNSYNCED);
}

TEST_F(ProductionAgeTest, ValueProducedHereIsExactOnOneClock) {
  ccomm_client* c = c_;
  const ccomm_signal pos = ccomm_find(c, "pos");
  const double x = 1.5;
  ASSERT_EQ(ccomm_write(c, pos, &x, sizeof x), 0);
  // Even with no clock synchronisation at all (nothing in the view).
  double got = 0;
  ccomm_info info{};
  ASSERT_GE(ccomm_read(c, pos, &got, sizeof got, &info), 0);
  const int64_t before = platform::MonotonicNs() - static_cast<int64_t>(info.source_time_ns);
  const ccomm_production_age a = Age(pos, info);
  const int64_t after = platform::MonotonicNs() - static_cast<int64_t>(info.source_time_ns);
  EXPECT_EQ(a.code, CCOMM_PAGE_SAME_NODE);
  EXPECT_EQ(a.known, 1);
  EXPECT_EQ(a.error_ns, 0);
  EXPECT_GE(a.age_ns, before);
  EXPECT_LE(a.age_ns, after);
  // On this board's realtime clock: the write moved by the realtime - monotonic offset.
  const int64_t want = static_cast<int64_t>(info.source_time_ns) + platform::RealtimeOffsetNs();
  EXPECT_LE(std::llabs(a.production_time_ns - want), 100000);  // two clock readings apart
}

TEST_F(ProductionAgeTest, CppViewAndGrowableCallers) {
  ccomm::Client client("a");
  ASSERT_TRUE(client.ok());
  ccomm::SystemView view(client);
  ASSERT_TRUE(view.ok()) << view.error();
  auto sp = client.signal<double>("sp");
  ASSERT_TRUE(sp.valid());
  ccomm::Reading<double> r;
  r.info.seq = 1;
  r.info.source_time_ns = platform::MonotonicNs() - 10 * kMs;
  SetClock(0, kSynced, 0, platform::RealtimeOffsetNs());  // the grandmaster
  SetClock(1, kSyncing, kNoBound, platform::RealtimeOffsetNs());
  ccomm_production_age a = view.production_age(sp, r);
  ExpectUnknown(a, CCOMM_PAGE_PRODUCER_UNSYNCED);
  SetClock(1, kSynced, 500, platform::RealtimeOffsetNs());
  a = view.production_age(sp, r);
  EXPECT_EQ(a.code, CCOMM_PAGE_SYNCED);
  EXPECT_EQ(a.error_ns, 500 + 2000);
  EXPECT_GE(a.age_ns, 10 * kMs - a.error_ns);
  // Growable: a caller built with a larger struct gets the rest zeroed; a smaller one is refused.
  struct Bigger {
    ccomm_production_age a;
    uint64_t more;
  } big;
  big.more = ~0ull;
  ASSERT_EQ(ccomm_view_production_age_sized(view.raw(), sp.id(), &r.info, &big.a, sizeof big), 0);
  EXPECT_EQ(big.more, 0u);
  EXPECT_EQ(big.a.code, CCOMM_PAGE_SYNCED);
  EXPECT_EQ(ccomm_view_production_age_sized(view.raw(), sp.id(), &r.info, &big.a, 8), CCOMM_E_INVAL);
  EXPECT_EQ(ccomm_view_production_age(view.raw(), 99, &r.info, &a), CCOMM_E_INVAL);
  EXPECT_EQ(ccomm_view_production_age(view.raw(), sp.id(), nullptr, &a), CCOMM_E_INVAL);
}

TEST(ProductionAgeName, EveryCodeHasTheNameToolsRecord) {
  EXPECT_STREQ(ccomm_production_age_name(CCOMM_PAGE_SYNCED), "synced");
  EXPECT_STREQ(ccomm_production_age_name(CCOMM_PAGE_SAME_NODE), "same_node");
  EXPECT_STREQ(ccomm_production_age_name(CCOMM_PAGE_NEVER), "never");
  EXPECT_STREQ(ccomm_production_age_name(CCOMM_PAGE_LOCAL_UNSYNCED), "local_unsynced");
  EXPECT_STREQ(ccomm_production_age_name(CCOMM_PAGE_PRODUCER_UNSYNCED), "producer_unsynced");
  EXPECT_STREQ(ccomm_production_age_name(CCOMM_PAGE_NO_SUMMARY), "no_summary");
  EXPECT_STREQ(ccomm_production_age_name(6), "?");
  EXPECT_STREQ(ccomm_production_age_name(-1), "?");
}

}  // namespace
}  // namespace ccomm
