// SPDX-License-Identifier: Apache-2.0
// Segment creation, client open, adoption across a daemon restart, replacement on a
// configuration change (old clients see "retired").
#include "store/segment.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <string.h>

#include "common/platform.h"
#include "store/reclaim.h"
#include <sys/wait.h>

#include <atomic>
#include <thread>
#include <unistd.h>
#include "daemon/engine/segment_builder.h"
#include "testing/test_config.h"

namespace ccomm {
namespace store {
namespace {

using testing::MakeSignal;
using testing::TwoNodeConfig;

class SegmentTest : public ::testing::Test {
 protected:
  void SetUp() override { setenv("CCOMM_SHM_PREFIX", testing::UniquePrefix("seg").c_str(), 1); }
  void TearDown() override { platform::ShmUnlink(SegmentName("a").c_str()); }
  SystemConfig Cfg() {
    auto s1 = MakeSignal("pos", ValueType::kDouble, 1, SignalKind::kState, 0, {1});
    s1.has_safe_value = true;
    s1.safe_value.assign(8, 0);
    auto s2 = MakeSignal("sp", ValueType::kFloat, 3, SignalKind::kState, 1, {0});
    auto s3 = MakeSignal("estop", ValueType::kBool, 1, SignalKind::kEvent, 0, {1});
    s3.queue_depth = 16;
    return TwoNodeConfig({s1, s2, s3});
  }
};

TEST_F(SegmentTest, CreateThenOpenSeesDirectory) {
  SystemConfig cfg = Cfg();
  Segment d;
  bool adopted = true;
  std::string err;
  ASSERT_EQ(CreateOrAdoptSegment(&d, cfg, 0, SegmentName("a"), -1, &adopted, &err), 0) << err;
  EXPECT_FALSE(adopted);
  Segment c;
  ASSERT_EQ(c.Open(SegmentName("a")), 0);
  EXPECT_EQ(c.signal_count(), 3u);
  EXPECT_EQ(c.Find("sp"), 1);
  EXPECT_EQ(c.Find("nope"), -1);
  EXPECT_TRUE(c.dir(0).flags & kSigForwarded);
  EXPECT_TRUE(c.dir(1).flags & kSigConsumedHere);
  EXPECT_TRUE(c.dir(2).flags & kSigEvent);
  EXPECT_EQ(c.dir(1).value_bytes, 12u);
  EXPECT_STREQ(c.node_name(1), "b");
  EXPECT_NE(c.safe_value(0), nullptr);
  EXPECT_EQ(c.safe_value(1), nullptr);
}

// Clients can write over the whole mapping: whoever mapped the segment before keeps its
// private layout (nothing it follows changes), and whoever opens it afterwards refuses a
// layout that points outside the segment instead of following it.
TEST_F(SegmentTest, LayoutWrittenOverIsNeitherFollowedNorAccepted) {
  SystemConfig cfg = Cfg();
  Segment d;
  bool adopted = true;
  std::string err;
  ASSERT_EQ(CreateOrAdoptSegment(&d, cfg, 0, SegmentName("a"), -1, &adopted, &err), 0) << err;
  Segment before;
  ASSERT_EQ(before.Open(SegmentName("a")), 0);
  const uint64_t data0 = d.dir(0).data_offset;
  auto* dir = At<SignalDirectoryEntry>(d.base(), d.header()->directory_offset);
  dir[0].data_offset = uint64_t{1} << 40;  // a stray write
  d.header()->signal_stats_offset = ~uint64_t{0};
  EXPECT_EQ(d.dir(0).data_offset, data0);
  EXPECT_EQ(before.dir(0).data_offset, data0);
  double v = 1.5;
  EXPECT_EQ(StateWrite(before.state(0), &v, 0, 1, 1), StoreResult::kOk);  // still the real cell
  before.stats(0).writes.fetch_add(1);
  Segment after;
  EXPECT_EQ(after.Open(SegmentName("a")), -EPROTO);
  EXPECT_NE(CheckLayout(d.base(), d.size()), "");
}

TEST_F(SegmentTest, RestartAdoptsAndKeepsValues) {
  SystemConfig cfg = Cfg();
  std::string err;
  bool adopted;
  Segment client;
  {
    Segment d;
    ASSERT_EQ(CreateOrAdoptSegment(&d, cfg, 0, SegmentName("a"), -1, &adopted, &err), 0);
    ASSERT_EQ(client.Open(SegmentName("a")), 0);
    double v = 4.25;
    ASSERT_EQ(StateWrite(client.state(0), &v, 0, 1, 1), StoreResult::kOk);
  }  // daemon gone
  Segment d2;
  ASSERT_EQ(CreateOrAdoptSegment(&d2, cfg, 0, SegmentName("a"), -1, &adopted, &err), 0);
  EXPECT_TRUE(adopted);
  EXPECT_EQ(d2.header()->generation.load(), 2u);
  double out = 0;
  SlotMeta m;
  ASSERT_EQ(StateRead(d2.state(0), &out, &m), StoreResult::kOk);
  EXPECT_EQ(out, 4.25);
  EXPECT_EQ(client.header()->state.load(), kReady);
}

TEST_F(SegmentTest, ConfigChangeRetiresOldSegment) {
  SystemConfig cfg = Cfg();
  std::string err;
  bool adopted;
  Segment d, client;
  ASSERT_EQ(CreateOrAdoptSegment(&d, cfg, 0, SegmentName("a"), -1, &adopted, &err), 0);
  ASSERT_EQ(client.Open(SegmentName("a")), 0);
  SystemConfig changed = cfg;
  changed.signals[1].count = 4;
  changed.hash += 1;
  Segment d2;
  ASSERT_EQ(CreateOrAdoptSegment(&d2, changed, 0, SegmentName("a"), -1, &adopted, &err), 0);
  EXPECT_FALSE(adopted);
  EXPECT_EQ(client.header()->state.load(), kRetired);
  Segment fresh;
  ASSERT_EQ(fresh.Open(SegmentName("a")), 0);
  EXPECT_EQ(fresh.dir(1).count, 4u);
}

// A client that sees its damaged segment retired and reopens at once must find the
// replacement or nothing yet (-ENOENT: wait), never the damaged one (-EPROTO: "layout
// version differs", which made a fresh-machine CI run's writer give up). The observer
// reopens the moment the old mapping says retired; repeated because the window it
// probes is a few microseconds wide.
TEST_F(SegmentTest, ClientReopeningDuringReplacementOfADamagedSegmentNeverSeesIt) {
  int saw_damaged = 0;
  const int rounds = 2000;
  for (int round = 0; round < rounds; ++round) {
    platform::ShmUnlink(SegmentName("a").c_str());
    Segment first, attached;
    std::string err;
    bool adopted;
    ASSERT_EQ(CreateOrAdoptSegment(&first, Cfg(), 0, SegmentName("a"), -1, &adopted, &err), 0) << err;
    ASSERT_EQ(attached.Open(SegmentName("a")), 0);
    first.header()->magic = 0xdeadbeef;  // garbage over the header: the next ccommd must replace it
    first.Close();
    std::atomic<int> reopen{1};
    std::thread client([&] {
      while (attached.header()->state.load(std::memory_order_acquire) != kRetired) {
      }
      Segment again;
      int r;
      while ((r = again.Open(SegmentName("a"))) == -ENOENT) {
      }
      reopen = r;
    });
    Segment second;
    ASSERT_EQ(CreateOrAdoptSegment(&second, Cfg(), 0, SegmentName("a"), -1, &adopted, &err), 0) << err;
    client.join();
    EXPECT_TRUE(reopen == 0 || reopen == -EPROTO) << reopen;
    if (reopen == -EPROTO) ++saw_damaged;
  }
  EXPECT_EQ(saw_damaged, 0) << "of " << rounds << " reopens";
}

TEST_F(SegmentTest, OpenMissingOrForeignSegment) {
  Segment c;
  EXPECT_EQ(c.Open(SegmentName("a")), -ENOENT);
  int fd = platform::ShmOpen(SegmentName("a").c_str(), true, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(platform::Truncate(fd, 4096), 0);
  platform::CloseFd(fd);
  // Zeros: what ccommd's segment looks like between ftruncate and filling it in. A
  // client must keep waiting (-ENOENT), not conclude the layout differs (-EPROTO).
  EXPECT_EQ(c.Open(SegmentName("a")), -ENOENT);
  fd = platform::ShmOpen(SegmentName("a").c_str(), false, 0);
  ASSERT_GE(fd, 0);
  void* p = platform::MapShared(fd, 4096);
  ASSERT_NE(p, nullptr);
  memset(p, 0xA5, 64);  // something else's data: not our magic
  platform::Unmap(p, 4096);
  platform::CloseFd(fd);
  EXPECT_EQ(c.Open(SegmentName("a")), -EPROTO);
  // The daemon replaces a foreign or half-created segment.
  Segment d;
  std::string err;
  bool adopted;
  ASSERT_EQ(CreateOrAdoptSegment(&d, Cfg(), 0, SegmentName("a"), -1, &adopted, &err), 0) << err;
  EXPECT_EQ(c.Open(SegmentName("a")), 0);
}

// Only slots of writers that are provably dead are given back.
TEST_F(SegmentTest, ReclaimFreesDeadWritersSlotsOnly) {
  SystemConfig cfg = Cfg();
  Segment d;
  std::string err;
  bool adopted;
  ASSERT_EQ(CreateOrAdoptSegment(&d, cfg, 0, SegmentName("a"), -1, &adopted, &err), 0);
  std::vector<SlotSuspect> suspects(SlotCount(d));
  EXPECT_EQ(SlotCount(d), (4u + 1u) + (4u + 1u) + 16u);  // states: 4 slots + the inline copy
  // A child claims a slot like a writer and dies before completing it.
  pid_t child = fork();
  if (child == 0) {
    StateView v = d.state(0);
    uint64_t t = v.cell->next_ticket.fetch_add(1);
    v.slot(t)->seq.store(2 * t + 1);
    v.slot(t)->owner.store((uint64_t{platform::ProcessId()} << 32) | t);
    // ... and, in another cell, dies while filling the inline copy.
    StateView w = d.state(1);
    w.cell->inline_claim.seq.store(2 * 7 + 1);
    w.cell->inline_claim.owner.store((uint64_t{platform::ProcessId()} << 32) | 7);
    w.cell->inline_seq.store(2 * 7 + 1);
    _exit(0);
  }
  waitpid(child, nullptr, 0);
  // This live process holds another slot of the same cell.
  StateView v = d.state(0);
  uint64_t t = v.cell->next_ticket.fetch_add(1);
  v.slot(t)->seq.store(2 * t + 1);
  v.slot(t)->owner.store((uint64_t{platform::ProcessId()} << 32) | t);
  EXPECT_EQ(ReclaimAbandonedSlots(d, &suspects), 2u);
  EXPECT_EQ(v.slot(0)->seq.load(), 0u);       // the dead child's slot: free again
  EXPECT_EQ(d.state(1).cell->inline_claim.seq.load(), 0u);
  EXPECT_EQ(v.slot(t)->seq.load(), 2 * t + 1);  // ours: untouched
  // A writer that died before writing its owner word: freed only after it stayed so for
  // kUnknownOwnerScans further scans.
  RingView r = d.ring(2);
  r.slot(5)->seq.store(2 * 5 + 1);
  for (uint32_t k = 0; k < kUnknownOwnerScans; ++k) EXPECT_EQ(ReclaimAbandonedSlots(d, &suspects), 0u) << k;
  EXPECT_EQ(ReclaimAbandonedSlots(d, &suspects), 1u);
  EXPECT_EQ(r.slot(5)->seq.load(), 0u);
}

// A writer killed after filling the readers' line copy but before publishing `latest`:
// readers may have taken the copy, so the reclaim publishes the (complete) slot of that
// ticket before freeing the claim, and values never go back once the copy is refilled.
TEST_F(SegmentTest, ReclaimPublishesADeadInlineWritersValue) {
  Segment d;
  std::string err;
  bool adopted;
  ASSERT_EQ(CreateOrAdoptSegment(&d, Cfg(), 0, SegmentName("a"), -1, &adopted, &err), 0);
  std::vector<SlotSuspect> suspects(SlotCount(d));
  StateView v = d.state(0);  // "pos", one double
  double x = 1.0;
  ASSERT_EQ(StateWrite(v, &x, 0, 1, 1), StoreResult::kOk);  // ticket 0, published
  pid_t child = fork();
  if (child == 0) {
    // Ticket 1: slot complete, line copy filled, claim held, `latest` not raised.
    uint64_t t = v.cell->next_ticket.fetch_add(1);
    double y = 2.0;
    SlotHeader* h = v.slot(t);
    ASSERT_TRUE(ClaimCopy(h, t));
    PublishSlot(h, t, 8, &y, SlotMeta{t + 1, 2, 2});
    ASSERT_TRUE(ClaimInline(v, t));
    FillInline(v, t, SlotMeta{t + 1, 2, 2}, &y);
    _exit(0);
  }
  waitpid(child, nullptr, 0);
  SlotMeta m;
  double out = 0;
  ASSERT_EQ(StateRead(v, &out, &m), StoreResult::kOk);
  EXPECT_EQ(out, 2.0);  // readers already see the dead writer's value in the line copy
  EXPECT_EQ(v.cell->latest.load(), 1u);
  EXPECT_EQ(ReclaimAbandonedSlots(d, &suspects), 1u);
  EXPECT_EQ(v.cell->latest.load(), 2u);  // published before the claim was freed
  EXPECT_EQ(v.cell->inline_claim.seq.load(), 0u);
  // The next writer refills the copy; a reader caught in the middle falls back to the
  // slot of `latest`: 2.0, never the older 1.0.
  uint64_t t = v.cell->next_ticket.fetch_add(1);
  ASSERT_TRUE(ClaimInline(v, t));
  v.cell->inline_seq.store(2 * t + 1);  // being refilled
  ASSERT_EQ(StateRead(v, &out, &m), StoreResult::kOk);
  EXPECT_EQ(out, 2.0);
}

}  // namespace
}  // namespace store
}  // namespace ccomm
