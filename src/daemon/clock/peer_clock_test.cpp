// SPDX-License-Identifier: Apache-2.0
// A peer's clock bounded from its frames (peer_clock.h): the minimum filter on its own,
// and on a real Daemon over loopback UDP, where a frame sent long before it arrives
// (queued) gives its value that age and is counted, while frames that arrive at once do not.
#include "daemon/clock/peer_clock.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "daemon/engine/receiving_daemon_fixture.h"
#include "testing/test_config.h"

namespace ccomm {
namespace {

constexpr uint64_t kMs = 1'000'000, kS = 1'000'000'000;

TEST(PeerClock, DelayIsMeasuredAgainstTheFastestFrame) {
  PeerClock c;
  const uint64_t offset = 77 * kS;  // our clock is 77 s ahead of the peer's
  EXPECT_EQ(c.Observe(1 * kS, 1 * kS + offset + 300'000), 0u);  // first frame: the floor
  EXPECT_EQ(c.Observe(1 * kS + 10 * kMs, 1 * kS + 10 * kMs + offset + 100'000), 0u);  // faster: new floor
  EXPECT_EQ(c.Observe(1 * kS + 20 * kMs, 1 * kS + 20 * kMs + offset + 150'000), 50'000u);
  EXPECT_EQ(c.floor_ns(), static_cast<int64_t>(offset + 100'000));
  // Sent 5 s before it arrives: 5 s beyond the floor.
  EXPECT_EQ(c.Observe(1 * kS, 6 * kS + offset + 100'000), 5 * kS);
}

TEST(PeerClock, AfterASilenceTheFloorBeforeItJudgesTheQueuedFrames) {
  PeerClock c;
  uint64_t t = 10 * kS;
  for (int i = 0; i < 50; ++i, t += 10 * kMs) c.Observe(t, t + 200'000);  // 0.5 s of normal frames
  // We were stopped for 5 s: the frames queued meanwhile arrive together now, all
  // sent 3-5 s ago; then normal frames again.
  const uint64_t resumed = t + 5 * kS;
  for (uint64_t sent = t; sent < t + 2 * kS; sent += 10 * kMs)
    EXPECT_GE(c.Observe(sent, resumed), 3 * kS - 200'000) << "a queued frame judged on the floor of the queue";
  for (int i = 1; i < 700; ++i) {  // 7 s of normal frames: two buckets turn over
    const uint64_t sent = resumed + static_cast<uint64_t>(i) * 10 * kMs;
    EXPECT_LT(c.Observe(sent, sent + 250'000), 100'000u) << "frame " << i << " after the queue";
  }
}

TEST(PeerClock, DriftMovesTheFloorOnlyOverTheWindow) {
  // Our clock runs 200 ppm fast: a frame's arrival - send grows 200 us per second. Old
  // minima leave the window, so the estimate stays within rho * 2 buckets (0.8 ms).
  PeerClock c;
  uint64_t worst = 0;
  for (uint64_t sent = 0; sent < 60 * kS; sent += 10 * kMs) {
    const uint64_t arrival = sent + sent / 5000 + 100'000;
    const uint64_t d = c.Observe(sent, arrival);
    worst = d > worst ? d : worst;
  }
  EXPECT_LE(worst, 2 * PeerClock::kBucketNs / 5000 + 10 * kMs / 5000);
  EXPECT_GT(worst, 0u);
}

TEST(PeerClock, ResetForgetsTheOldClock) {
  PeerClock c;
  c.Observe(1000 * kS, 1000 * kS + 100'000);
  c.Reset();  // the peer rebooted: its clock starts near 0
  EXPECT_FALSE(c.known());
  EXPECT_EQ(c.Observe(1 * kS, 1001 * kS), 0u);
  EXPECT_EQ(c.Observe(1 * kS + kMs, 1001 * kS + kMs), 0u);
}

// One forged frame (no key) stamped an hour ahead: x is an hour below the floor. Genuine
// frames after it read an hour queued (stale, with an age of our uptime) until the window
// turned over, 2-4 s, and for good while the peer was quiet. Now one heartbeat interval at most.
TEST(PeerClock, AForgedFutureStampHoldsTheFloorDownOneHeartbeatIntervalAtMost) {
  constexpr uint64_t kHeartbeat = 100 * kMs, kHour = 3600 * kS;
  for (const bool quiet : {false, true}) {
    PeerClock c;
    c.set_confirm_window_ns(kHeartbeat);
    uint64_t t = 10 * kS;
    for (int i = 0; i < 100; ++i, t += 10 * kMs) c.Observe(t, t + 200'000);  // 1 s of normal frames
    const int64_t floor = c.floor_ns();
    EXPECT_EQ(c.Observe(t + kHour, t + 200'000), 0u);  // the forged frame
    const uint64_t forged_at = t + 200'000;
    if (quiet) t += 60 * kS;  // the peer says nothing for a minute
    for (int i = 1; i <= 300; ++i) {
      const uint64_t sent = t + static_cast<uint64_t>(i) * 10 * kMs, arrival = sent + 250'000;
      const uint64_t d = c.Observe(sent, arrival);
      if (arrival > forged_at + kHeartbeat) {
        EXPECT_LT(d, kMs) << (quiet ? "after a quiet minute, " : "") << "frame " << i << " read queued "
                          << d << " ns, " << (arrival - forged_at) / kMs << " ms after the forged one";
      }
    }
    EXPECT_LT(c.floor_ns() > floor ? c.floor_ns() - floor : floor - c.floor_ns(), static_cast<int64_t>(kMs));
  }
}

TEST(PeerClock, AForgedFutureStampAfterAResetIsNotTheFloorForLong) {
  // A forged frame with a lower seq and a later stamp reads as the peer's restart (rule 5):
  // the floor is reset and the forged frame is the first of the new clock.
  constexpr uint64_t kHeartbeat = 100 * kMs;
  PeerClock c;
  c.set_confirm_window_ns(kHeartbeat);
  c.Observe(5 * kS, 5 * kS + 100'000);
  c.Reset();
  c.Observe(5 * kS + 3600 * kS, 5 * kS + 200'000);
  for (int i = 1; i <= 50; ++i) {
    const uint64_t sent = 5 * kS + static_cast<uint64_t>(i) * 10 * kMs;
    const uint64_t d = c.Observe(sent, sent + 150'000);
    if (i * 10 * kMs > kHeartbeat) {
      EXPECT_LT(d, kMs) << "frame " << i;
    }
  }
}

TEST(PeerClock, AFasterPathIsTakenOnTheSecondFrame) {
  // The first frames came queued by 50 ms (start-up), then the path is fast: the lower floor
  // is confirmed by the next frame at once, so a later queued frame is recognised.
  PeerClock c;
  for (uint64_t i = 0; i < 5; ++i) c.Observe(i * 10 * kMs, i * 10 * kMs + 50 * kMs);
  EXPECT_EQ(c.Observe(60 * kMs, 60 * kMs + 100'000), 0u);
  EXPECT_EQ(c.Observe(70 * kMs, 70 * kMs + 100'000), 0u);
  EXPECT_EQ(c.Observe(80 * kMs, 80 * kMs + 30 * kMs + 100'000), 30 * kMs);
  for (uint64_t i = 0; i < 50; ++i) c.Observe(100 * kMs + i * 10 * kMs, 100 * kMs + i * 10 * kMs + 100'000);
  EXPECT_EQ(c.Observe(700 * kMs, 700 * kMs + 20 * kMs + 100'000), 20 * kMs) << "the fast floor stayed";
}

constexpr uint16_t kStateId = 1;

class QueuedFrameTest : public testing::ReceivingDaemonTest {
 protected:
  void SetUp() override {
    StartDaemon("peerclk", testing::PosAndSetpoint());
  }
  // A frame from b (node 1) sent at `send_ns` (b's clock = ours here) carrying sp = v.
  void Send(uint32_t seq, uint32_t value_seq, double v, uint64_t send_ns) {
    std::vector<uint8_t> buf(wire::kMaxFrameSize);
    wire::FrameWriter w(buf.data(), buf.size());
    w.Begin(PeerFrameHeader(seq, send_ns));
    ASSERT_TRUE(w.Add(kStateId, static_cast<uint8_t>(ValueType::kDouble), 0, 1, value_seq, send_ns, &v, 8));
    const size_t len = w.Finish();
    ASSERT_EQ(sendto(tx_, buf.data(), len, 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(len));
    const uint64_t want = ++sent_;
    for (int i = 0; i < 2000 && daemon_.segment().peer(1).frames_rx.load() < want; ++i) usleep(1000);
    ASSERT_EQ(daemon_.segment().peer(1).frames_rx.load(), want);
  }
  store::SlotMeta Meta() {
    double v = 0;
    store::SlotMeta m;
    EXPECT_EQ(store::StateRead(daemon_.segment().state(kStateId), &v, &m), store::StoreResult::kOk);
    return m;
  }
  uint64_t sent_ = 0;
};

TEST_F(QueuedFrameTest, AValueFromAQueuedFrameIsAsOldAsItsWait) {
  for (uint32_t i = 1; i <= 5; ++i) Send(i, i, 1.0 * i, platform::MonotonicNs());
  const store::PeerStats& ps = daemon_.segment().peer(1);
  EXPECT_EQ(ps.frames_delayed.load(), 0u);
  // Sent 5 s before it arrives (as if it had waited in our socket meanwhile).
  const uint64_t sent = platform::MonotonicNs() - 5 * kS;
  Send(6, 6, 6.0, sent);
  const store::SlotMeta m = Meta();
  EXPECT_EQ(m.value_seq, 6u);
  // Its arrival moved back by the wait beyond the floor (a loopback delay of microseconds
  // up to a loaded machine's milliseconds): its age is about 5 s, not about 0.
  EXPECT_LE(m.local_time_ns, sent + 500 * kMs);
  EXPECT_GE(m.local_time_ns, sent);
  EXPECT_EQ(ps.frames_delayed.load(), 1u);
  EXPECT_GE(ps.queue_delay_max_ns.load(), 4500 * kMs);
  // The next frame arrives at once again: its value is fresh.
  Send(7, 7, 7.0, platform::MonotonicNs());
  EXPECT_GE(Meta().local_time_ns + 500 * kMs, platform::MonotonicNs());
  EXPECT_EQ(ps.frames_delayed.load(), 1u);
}

TEST_F(QueuedFrameTest, AForgedFutureStampMakesGenuineValuesStaleOneHeartbeatIntervalAtMost) {
  for (uint32_t i = 1; i <= 5; ++i) Send(i, i, 1.0 * i, platform::MonotonicNs());
  // A frame of b, forged (no key is configured): an hour ahead of b's clock.
  const uint64_t forged_at = platform::MonotonicNs();
  Send(6, 6, 6.0, forged_at + 3600 * kS);
  // b's genuine frames every 20 ms for 0.5 s: past one heartbeat interval (100 ms) after the
  // forged frame, their values arrive fresh again (the age was the host's uptime for 2-4 s).
  uint32_t seq = 7;
  for (int i = 0; i < 25; ++i, ++seq) {
    usleep(20'000);
    const uint64_t sent = platform::MonotonicNs();
    Send(seq, seq, 1.0 * seq, sent);
    if (sent > forged_at + 150 * kMs) {
      const uint64_t age = platform::MonotonicNs() - Meta().local_time_ns;
      EXPECT_LT(age, 500 * kMs) << "value " << seq << ", " << (sent - forged_at) / kMs << " ms after the forged frame";
    }
  }
  EXPECT_LT(daemon_.segment().peer(1).queue_delay_ns.load(), 10 * kMs);
}

}  // namespace
}  // namespace ccomm
