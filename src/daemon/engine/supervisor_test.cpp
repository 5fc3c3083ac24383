// SPDX-License-Identifier: Apache-2.0
// The supervision's schedule (Supervisor::NextTickNs) on a real Daemon over loopback UDP:
// idle or while a produced signal is written it ticks every 100 ms, not every 10 ms (the
// summary reads the signal's age off its newest value); a consumed signal going stale and
// a peer's timeout are ticked at their instant (counted then), not up to 100 ms later.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "daemon/engine/receiving_daemon_fixture.h"
#include "daemon/engine/supervisor.h"
#include "store/state_slot.h"
#include "store/view.h"
#include "testing/test_config.h"
#include "wire/wire.h"

namespace ccomm {
namespace {

constexpr uint16_t kPos = 0, kSp = 1;  // pos: produced here (a); sp: produced by b, consumed here
constexpr uint64_t kMs = 1000000;
constexpr uint32_t kStaleAfterMs = 30;

class SupervisorScheduleTest : public testing::ReceivingDaemonTest {
 protected:
  void SetUp() override {
    auto pos = testing::MakeSignal("pos", ValueType::kDouble, 1, SignalKind::kState, 0, {1});
    auto sp = testing::MakeSignal("sp", ValueType::kDouble, 1, SignalKind::kState, 1, {0});
    sp.stale_after_ms = kStaleAfterMs;
    opt_.ptp_socket = "";  // no clock to ask: its polls do not enter the schedule
    StartDaemon("supsched", {pos, sp});
    started_ns_ = platform::MonotonicNs();
  }
  // Past the start's own due work (the first summary parts), so that what a test plans
  // is the only thing due.
  void WaitPastTheFirstSecond() {
    while (platform::MonotonicNs() < started_ns_ + 1005 * kMs) usleep(20000);
  }
  // One frame from b carrying sp = v; returns once the receive thread stored it.
  void SendSp(uint32_t seq, double v) {
    std::vector<uint8_t> buf(wire::kMaxFrameSize);
    wire::FrameWriter w(buf.data(), buf.size());
    wire::FrameHeader h = PeerFrameHeader(seq, platform::MonotonicNs());
    w.Begin(h);
    ASSERT_TRUE(w.Add(kSp, static_cast<uint8_t>(ValueType::kDouble), 0, 1, seq, h.send_time_ns, &v, 8));
    const size_t len = w.Finish();
    const uint64_t rx_before = Stats(kSp).rx.load();
    ASSERT_EQ(sendto(tx_, buf.data(), len, 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(len));
    for (int i = 0; i < 500 && Stats(kSp).rx.load() == rx_before; ++i) usleep(1000);
    ASSERT_EQ(Stats(kSp).rx.load(), rx_before + 1);
  }
  const store::SignalStats& Stats(uint32_t id) { return daemon_.segment().stats(id); }
  // An application's write of pos as the library makes it: the value into its state cell,
  // stamped with its write time `at`, and counted (the daemon only reads the segment).
  void WriteOfPos(double v, uint64_t at) {
    store::Segment& seg = const_cast<store::Segment&>(daemon_.segment());
    ASSERT_EQ(store::StateWrite(seg.state(kPos), &v, 0, at, at), store::StoreResult::kOk);
    seg.stats(kPos).writes.fetch_add(1);
  }
  // pos's age in this node's own record of the system view, as the last tick wrote it.
  uint32_t AgeOfPosMs() {
    store::View v;
    EXPECT_EQ(v.OpenReadOnly(store::View::NameFor("a")), 0);
    store::ViewRowCopy row;
    EXPECT_TRUE(v.ReadRow(0, kPos, &row));
    EXPECT_TRUE(row.present);
    return row.age_ms;
  }
  uint64_t started_ns_ = 0;
  uint64_t Tick(uint64_t now) {
    daemon_.Supervise(now);
    return daemon_.NextSupervisionNs() - now;
  }
};

TEST_F(SupervisorScheduleTest, IdleOrWrittenTicksEvery100ms) {
  // One second of ticks, each at the instant the last one planned; `write`: pos is
  // written before every tick (as a 100 Hz or faster writer would).
  uint64_t now = platform::MonotonicNs() + 2000 * kMs;
  double v = 0;
  auto second = [&](bool write) {
    int ticks = 0;
    uint64_t longest = 0;
    for (const uint64_t end = now + 1000 * kMs; now < end; ++ticks) {
      if (write) WriteOfPos(v += 1, now);
      const uint64_t wait = Tick(now);
      EXPECT_GE(wait, Supervisor::kTickNs);
      EXPECT_LE(wait, Supervisor::kIdleTickNs);
      longest = std::max(longest, wait);
      now += wait;
    }
    return std::make_pair(ticks, longest);
  };
  auto idle = second(false);
  EXPECT_LE(idle.first, 11) << "idle: about 10 ticks a second";
  EXPECT_EQ(idle.second, Supervisor::kIdleTickNs);
  EXPECT_EQ(AgeOfPosMs(), wire::kSummaryNoAge) << "never written";
  // Written: no more ticks than idle (they used to come every 10 ms for a second after a
  // write, to sample when the writes advanced).
  auto written = second(true);
  EXPECT_LE(written.first, 11) << "written: about 10 ticks a second, as idle";
  EXPECT_EQ(written.second, Supervisor::kIdleTickNs);
  // The age in the summary is read off the value's own write time, to the ms: a value
  // stamped 300 ms before the next tick (its writer's clock), then ticked as scheduled
  // until the record is refreshed (at its summary part's instant). The old sampling
  // dated the value by the first tick that saw the write count move: 300 ms younger.
  const uint64_t written_at = now - 300 * kMs;
  WriteOfPos(v += 1, written_at);
  uint64_t ticked = now;
  for (int i = 0; i < 40; ++i) {
    ticked = now;
    now += Tick(now);
    if (AgeOfPosMs() >= 300) break;
  }
  EXPECT_EQ(AgeOfPosMs(), (ticked - written_at) / kMs);
  EXPECT_LE(ticked, written_at + 1300 * kMs) << "a record is refreshed at least once a second";
}

TEST_F(SupervisorScheduleTest, StaleAndPeerTimeoutAreTickedAtTheirInstant) {
  WaitPastTheFirstSecond();
  SendSp(1, 1.5);
  const uint64_t last = Stats(kSp).last_rx_ns.load();
  const uint64_t peer_last = daemon_.segment().peer(1).last_rx_ns.load();
  ASSERT_EQ(daemon_.segment().peer(1).alive.load(), 1u);
  // Fresh now; stale at last + stale_after: the next tick is then, not 100 ms later.
  const uint64_t stale_at = last + kStaleAfterMs * kMs + 1;
  uint64_t now = last + 5 * kMs;
  EXPECT_EQ(now + Tick(now), stale_at);
  EXPECT_EQ(Stats(kSp).stale_transitions.load(), 0u);
  now = stale_at;
  const uint64_t timeout_ns = uint64_t{cfg_.network.peer_timeout_ms} * kMs;
  const uint64_t lost_at = peer_last + timeout_ns + 1;
  const uint64_t next = Tick(now);
  EXPECT_EQ(Stats(kSp).stale_transitions.load(), 1u) << "counted at the tick of its instant";
  EXPECT_GT(next, Supervisor::kTickNs);  // nothing else due soon: idle again
  EXPECT_LE(next, Supervisor::kIdleTickNs);
  // The peer's timeout: ticked at its instant, the peer counted down then.
  now = lost_at - Supervisor::kIdleTickNs / 2;
  EXPECT_EQ(now + Tick(now), lost_at);
  EXPECT_EQ(daemon_.segment().peer(1).down_transitions.load(), 0u);
  Tick(lost_at);
  EXPECT_EQ(daemon_.segment().peer(1).alive.load(), 0u);
  EXPECT_EQ(daemon_.segment().peer(1).down_transitions.load(), 1u);
}

TEST_F(SupervisorScheduleTest, NeverSoonerThanTheFixedTick) {
  WaitPastTheFirstSecond();
  SendSp(1, 2.5);
  // 1 ms before sp goes stale: the tick waits the full 10 ms (no more ticks than before).
  const uint64_t now = Stats(kSp).last_rx_ns.load() + (kStaleAfterMs - 1) * kMs;
  EXPECT_EQ(Tick(now), Supervisor::kTickNs);
}

}  // namespace
}  // namespace ccomm
