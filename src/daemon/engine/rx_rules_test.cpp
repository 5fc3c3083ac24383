// SPDX-License-Identifier: Apache-2.0
// Receiver rules 2, 5 and 6 of docs/protocol.md on a real Daemon over loopback UDP:
// sequence numbers cross 0xFFFFFFFF (serial arithmetic, values keep flowing, exact loss
// counts), one sender's unicast and broadcast streams are separate, a forged frame that
// jumps far ahead is followed by resynchronisation, and a frame from an address that
// is not the sender's is refused and counted.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>
#include <thread>
#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "daemon/engine/receiving_daemon_fixture.h"
#include "testing/test_config.h"

namespace ccomm {
namespace {

constexpr uint16_t kStateId = 1, kEventId = 2;

class RxRulesTest : public testing::ReceivingDaemonTest {
 protected:
  void SetUp() override {
    // Node a (0) is the daemon under test; b (1) produces "sp" (state) and "ev" (event).
    auto pos = testing::MakeSignal("pos", ValueType::kDouble, 1, SignalKind::kState, 0, {1});
    auto sp = testing::MakeSignal("sp", ValueType::kDouble, 1, SignalKind::kState, 1, {0});
    auto ev = testing::MakeSignal("ev", ValueType::kDouble, 1, SignalKind::kEvent, 1, {0});
    ev.queue_depth = 64;
    StartDaemon("rxrules", {pos, sp, ev});
  }
  static int Socket(const char* ip) { return BoundSocket(ip); }
  // One frame from b with frame seq `seq` to `dest`, carrying `signal` = v with value seq
  // `value_seq` (no entry if signal is 0xFFFF: a heartbeat).
  void Send(uint32_t seq, uint16_t dest, uint16_t signal, uint32_t value_seq, double v, uint64_t send_ns = 0,
            int fd = -1) {
    std::vector<uint8_t> buf(wire::kMaxFrameSize);
    wire::FrameWriter w(buf.data(), buf.size());
    wire::FrameHeader h;
    h.sender = 1;
    h.dest = dest;
    h.config_hash = cfg_.hash;
    h.seq = seq;
    h.send_time_ns = send_ns ? send_ns : platform::MonotonicNs();
    if (signal == 0xFFFF) h.flags = wire::kFlagHeartbeat;
    w.Begin(h);
    if (signal != 0xFFFF) {
      const uint8_t flags = signal == kEventId ? wire::kEntryEvent : 0;
      ASSERT_TRUE(w.Add(signal, static_cast<uint8_t>(ValueType::kDouble), flags, 1, value_seq, h.send_time_ns, &v, 8));
    }
    size_t len = w.Finish();
    ASSERT_GT(len, 0u);
    if (version_ != 0) buf[4] = version_;  // a board of another wire version
    ASSERT_EQ(sendto(fd >= 0 ? fd : tx_, buf.data(), len, 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(len));
    ++sent_;
  }
  uint64_t Counter(store::DaemonCounter c) { return daemon_.segment().header()->daemon_counters[c].load(); }
  // Every frame ends in exactly one of these counters.
  void WaitHandled() {
    for (int i = 0; i < 400; ++i) {
      uint64_t t = Counter(store::kFramesRx) + Counter(store::kFramesUnknownSender) +
                   Counter(store::kFramesWrongSource) + Counter(store::kFramesBad) +
                   Counter(store::kFramesWrongHash) + Counter(store::kFramesNotForUs);
      if (t >= sent_) return;
      usleep(2000);
    }
    FAIL() << "daemon did not handle " << sent_ << " frames";
  }
  const store::PeerStats& Peer() { return daemon_.segment().peer(1); }
  const store::SignalStats& Stats(uint32_t id) { return daemon_.segment().stats(id); }
  double State(uint64_t* value_seq) {
    double v = 0;
    store::SlotMeta m;
    EXPECT_EQ(store::StateRead(daemon_.segment().state(kStateId), &v, &m), store::StoreResult::kOk);
    *value_seq = m.value_seq;
    return v;
  }

  uint64_t sent_ = 0;
  uint8_t version_ = 0;  // non-zero: Send writes this wire version instead of ours
};

TEST_F(RxRulesTest, FrameOfAnotherWireVersionIsCountedAndChangesNothing) {
  // docs/protocol.md, Versioning: a version-1 frame (a board from before the clock in
  // summaries) is refused as bad_version, counted in frames_bad, its value never stored.
  ASSERT_EQ(wire::kVersion, 2);
  version_ = 1;
  Send(1, 0, kStateId, 1, 7.0);
  WaitHandled();
  EXPECT_EQ(Counter(store::kFramesBad), 1u);
  EXPECT_EQ(Counter(store::kFramesRx), 0u);
  EXPECT_EQ(Stats(kStateId).rx.load(), 0u);
  version_ = 0;
  Send(2, 0, kStateId, 2, 8.0);
  WaitHandled();
  uint64_t seq = 0;
  EXPECT_EQ(State(&seq), 8.0);
  EXPECT_EQ(Counter(store::kFramesBad), 1u);
}

TEST_F(RxRulesTest, StateAndFrameSequencesCrossTheWrap) {
  // Frame and value sequences both cross 0xFFFFFFFF: every value is applied, nothing
  // counts as lost or reordered, and the stored sequence keeps growing past 2^32.
  const uint32_t first = 0xFFFFFFF0u;
  uint64_t prev_seq = 0;
  for (uint32_t i = 0; i < 40; ++i) {
    Send(first + i, 0, kStateId, first + i, 100.0 + i);
    WaitHandled();
    uint64_t seq = 0;
    EXPECT_EQ(State(&seq), 100.0 + i) << "value " << i << " (wire seq " << first + i << ") not applied";
    EXPECT_GT(seq, prev_seq);
    prev_seq = seq;
  }
  EXPECT_EQ(prev_seq, uint64_t{first} + 39);  // 64-bit: 0x100000017
  EXPECT_EQ(Stats(kStateId).rx.load(), 40u);
  EXPECT_EQ(Stats(kStateId).lost.load(), 0u);
  EXPECT_EQ(Peer().frames_lost.load(), 0u);
  EXPECT_EQ(Peer().frames_reordered.load(), 0u);
}

TEST_F(RxRulesTest, EventCrossingTheWrapIsNumberedAndCountedExactly) {
  // Events 0xFFFFFFFE, 0xFFFFFFFF, 0, [1 lost], 2, 3: five queued, exactly one lost.
  const uint32_t seqs[] = {0xFFFFFFFEu, 0xFFFFFFFFu, 0u, 2u, 3u};
  uint32_t frame = 7;
  for (uint32_t s : seqs) Send(frame++, 0, kEventId, s, static_cast<double>(s));
  WaitHandled();
  EXPECT_EQ(Stats(kEventId).rx.load(), 5u);
  EXPECT_EQ(Stats(kEventId).lost.load(), 1u);
  store::RingView ring = daemon_.segment().ring(kEventId);
  store::RingCursor cur;  // from the start of the ring
  uint64_t prev = 0;
  for (int i = 0; i < 5; ++i) {
    double v = 0;
    store::SlotMeta m;
    ASSERT_EQ(store::RingRead(ring, &cur, &v, &m, 0), store::StoreResult::kOk);
    EXPECT_EQ(v, static_cast<double>(seqs[i]));
    EXPECT_GT(m.value_seq, prev) << "event " << i << " numbered out of order";
    prev = m.value_seq;
  }
  EXPECT_EQ(prev, uint64_t{0xFFFFFFFEu} + 5);  // 0xFFFFFFFE, +1, +2, (+3 lost), +4, +5
}

TEST_F(RxRulesTest, UnicastAndBroadcastStreamsOfOneSenderAreSeparate) {
  // Rule 5: one counter per (sender, dest). Interleaved, neither stream loses a frame.
  for (uint32_t i = 0; i < 20; ++i) {
    Send(1000 + i, 0, kStateId, 1 + 2 * i, i);
    Send(50 + i, wire::kDestAll, 0xFFFF, 0, 0);
  }
  WaitHandled();
  EXPECT_EQ(Counter(store::kFramesRx), 40u);
  EXPECT_EQ(Peer().frames_lost.load(), 0u);
  EXPECT_EQ(Peer().frames_reordered.load(), 0u);
}

TEST_F(RxRulesTest, ForgedJumpAheadIsFollowedByResynchronisation) {
  // A frame without a key claiming b, with a huge frame seq, value seq and send time,
  // sets 999. The genuine stream must win back within kResyncAfter (4) frames.
  uint32_t frame = 1, value = 1;
  for (int i = 0; i < 5; ++i) Send(frame++, 0, kStateId, value++, 1.0);
  WaitHandled();
  Send(0x40000000u, 0, kStateId, 0x40000000u, 999.0, platform::MonotonicNs() + (3600ull << 30));
  WaitHandled();
  uint64_t seq = 0;
  EXPECT_EQ(State(&seq), 999.0);  // accepted: without a key it is indistinguishable
  int genuine = 0;
  for (; genuine < 10; ++genuine) {
    Send(frame++, 0, kStateId, value++, 2.0 + genuine);
    WaitHandled();
    if (State(&seq) != 999.0) break;
  }
  EXPECT_LT(genuine, 4) << "the genuine stream stayed locked out";
  const uint64_t before = seq;
  Send(frame++, 0, kStateId, value++, 42.0);
  WaitHandled();
  EXPECT_EQ(State(&seq), 42.0);  // and stays in sync afterwards
  EXPECT_GT(seq, before);        // readers' seq never goes back
}

TEST_F(RxRulesTest, FrameFromAForeignAddressIsCountedAndDropped) {
  int foreign = Socket("127.0.0.3");
  Send(1, 0, kStateId, 1, 5.0, 0, foreign);
  WaitHandled();
  EXPECT_EQ(Counter(store::kFramesWrongSource), 1u);
  EXPECT_EQ(Stats(kStateId).rx.load(), 0u);
  Send(2, 0, kStateId, 2, 6.0);  // from b's own address
  WaitHandled();
  uint64_t seq = 0;
  EXPECT_EQ(State(&seq), 6.0);
  close(foreign);
}

}  // namespace
}  // namespace ccomm
