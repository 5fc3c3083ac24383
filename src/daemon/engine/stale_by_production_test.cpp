// SPDX-License-Identifier: Apache-2.0
// stale_by="production" (docs/design.md, "Time"): a consumer ccommd stamps a value with
// its write time on the producer, mapped onto this board's clock through the common time
// base, while both clocks are synced (the producer's from its node summary, this board's
// from its supervision); otherwise with its arrival, as without the option. A value
// written 200 ms before it arrived then reads as 200 ms old, i.e. stale after 50 ms.
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "daemon/engine/receiving_daemon_fixture.h"
#include "store/seqlock.h"
#include "testing/test_config.h"
#include "wire/summary.h"
#include "wire/wire.h"

namespace ccomm {
namespace {

constexpr uint16_t kByProduction = 1, kByArrival = 2;
constexpr uint64_t kMs = 1000000;

class StaleByProductionTest : public testing::ReceivingDaemonTest {
 protected:
  void SetUp() override {
    // Node a (0) is the daemon under test; b (1) produces both signals.
    std::vector<SignalConfig> signals = testing::PosAndSetpoint();
    signals[1].stale_after_ms = 50;
    signals[1].stale_by = StaleBy::kProduction;
    signals.push_back(testing::MakeSignal("sq", ValueType::kDouble, 1, SignalKind::kState, 1, {0}));
    signals.back().stale_after_ms = 50;
    StartDaemon("staleby", signals);
  }
  void SendFrame(std::vector<uint8_t>& buf, size_t len) {
    ASSERT_GT(len, 0u);
    ASSERT_EQ(sendto(tx_, buf.data(), len, 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(len));
    ++sent_;
    WaitHandled();
  }
  // b's node summary, its clock in `state` with realtime - monotonic `offset`.
  void SendSummary(uint8_t state, int64_t offset) {
    std::vector<uint8_t> buf(wire::kMaxFrameSize);
    wire::FrameHeader h;
    h.flags = wire::kFlagSummary;
    h.sender = 1;
    h.dest = 0;
    h.config_hash = cfg_.hash;
    h.seq = summary_seq_++;
    h.send_time_ns = platform::MonotonicNs();
    wire::SummaryHead head;
    head.clock_state = state;
    head.clock_error_ns = state == 2 ? 5000 : wire::kSummaryNoClockError;
    head.clock_offset_ns = offset;
    wire::SummaryWriter w(buf.data(), buf.size());
    ASSERT_TRUE(w.Begin(h, head));
    SendFrame(buf, w.Finish());
  }
  // Both signals' values, written `written_ago` before now on b's monotonic clock.
  void SendValues(uint32_t seq, uint64_t b_monotonic_now, uint64_t written_ago) {
    std::vector<uint8_t> buf(wire::kMaxFrameSize);
    wire::FrameWriter w(buf.data(), buf.size());
    w.Begin(PeerFrameHeader(seq, b_monotonic_now));
    const double v = seq;
    const uint8_t dbl = static_cast<uint8_t>(ValueType::kDouble);
    ASSERT_TRUE(w.Add(kByProduction, dbl, 0, 1, seq, b_monotonic_now - written_ago, &v, 8));
    ASSERT_TRUE(w.Add(kByArrival, dbl, 0, 1, seq, b_monotonic_now - written_ago, &v, 8));
    SendFrame(buf, w.Finish());
  }
  uint64_t Counter(store::DaemonCounter c) { return daemon_.segment().header()->daemon_counters[c].load(); }
  void WaitHandled() {
    for (int i = 0; i < 2000; ++i) {
      uint64_t t = Counter(store::kFramesRx) + Counter(store::kFramesBad) + Counter(store::kFramesUnknownSender) +
                   Counter(store::kFramesWrongSource) + Counter(store::kFramesWrongHash) +
                   Counter(store::kFramesNotForUs) + Counter(store::kEntriesUnknownSignal);
      if (t >= sent_) return;
      usleep(2000);
    }
    FAIL() << "daemon did not handle " << sent_ << " frames";
  }
  // Local stamp of the value of `id` (what its age counts from) and when the test read it.
  uint64_t Stamp(uint16_t id) {
    double v = 0;
    store::SlotMeta m;
    EXPECT_EQ(store::StateRead(daemon_.segment().state(id), &v, &m), store::StoreResult::kOk);
    return m.local_time_ns;
  }

  uint64_t sent_ = 0;
  uint32_t summary_seq_ = 0;
};

TEST_F(StaleByProductionTest, AgeCountsFromTheWriteOnlyWhileBothClocksAreSynced) {
  // Board b's monotonic clock runs 1000 s ahead of ours: its offset to the common time
  // base is 1000 s smaller. Its values were written 200 ms before they were sent.
  const int64_t b_ahead = 1000000 * int64_t{kMs};
  const auto b_now = [&] { return platform::MonotonicNs() + static_cast<uint64_t>(b_ahead); };
  const auto b_offset = [&] { return platform::RealtimeOffsetNs() - b_ahead; };

  // 1. Neither clock synced: the arrival, for both signals.
  SendSummary(1, b_offset());
  uint64_t before = platform::MonotonicNs();
  SendValues(1, b_now(), 200 * kMs);
  EXPECT_GE(Stamp(kByProduction), before);
  EXPECT_GE(Stamp(kByArrival), before);

  // 2. b synced, this board not: still the arrival (never a production time from one clock).
  SendSummary(2, b_offset());
  before = platform::MonotonicNs();
  SendValues(2, b_now(), 200 * kMs);
  EXPECT_GE(Stamp(kByProduction), before);

  // 3. Both synced: the production time on our clock, 200 ms before the send; the
  //    other signal keeps its arrival.
  daemon_.PublishSelfClock(true, platform::RealtimeOffsetNs());
  const uint64_t sent_at = platform::MonotonicNs();
  SendValues(3, b_now(), 200 * kMs);
  const uint64_t stamp = Stamp(kByProduction);
  EXPECT_LE(stamp, sent_at - 200 * kMs + 1 * kMs);  // mapped through the two offsets (< 1 ms apart)
  EXPECT_GE(stamp + 2 * kMs, sent_at - 200 * kMs);
  EXPECT_GE(Stamp(kByArrival), sent_at);
  // So it reads stale at once (200 ms > stale_after_ms 50), where the arrival would be fresh.
  EXPECT_GE(platform::MonotonicNs() - stamp, 200 * kMs);

  // 4. b's clock lost: back to the arrival.
  SendSummary(3, b_offset());
  before = platform::MonotonicNs();
  SendValues(4, b_now(), 200 * kMs);
  EXPECT_GE(Stamp(kByProduction), before);
  // A stamp is never later than the arrival, whatever the clocks claim (a producer "ahead").
  SendSummary(2, b_offset() + 10000 * int64_t{kMs});
  before = platform::MonotonicNs();
  SendValues(5, b_now(), 0);
  const uint64_t after = platform::MonotonicNs();
  EXPECT_GE(Stamp(kByProduction), before);
  EXPECT_LE(Stamp(kByProduction), after);
}

}  // namespace
}  // namespace ccomm
