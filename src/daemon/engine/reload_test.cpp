// SPDX-License-Identifier: Apache-2.0
// Reload (Daemon::ReloadRefusal / Reconfigure, daemon_reload.cpp) on a real Daemon over
// loopback UDP, with the receive thread stopped and started around Reconfigure as main()
// does: a local change keeps the segment and what the receive path knew of each peer
// and signal (a value already applied is not applied again, no loss is counted); a
// signal change replaces the segment (the old one says retired, frames of the old
// configuration are refused); a change of what the socket was opened from is refused.
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <string>
#include <thread>
#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "daemon/engine/receiving_daemon_fixture.h"
#include "store/layout.h"
#include "store/state_slot.h"
#include "testing/test_config.h"

namespace ccomm {
namespace {

constexpr uint16_t kPos = 0, kSp = 1;  // a -> b and b -> a, states

class ReloadTest : public testing::ReceivingDaemonTest {
 protected:
  void SetUp() override {
    auto pos = testing::MakeSignal("pos", ValueType::kDouble, 1, SignalKind::kState, 0, {1});
    auto sp = testing::MakeSignal("sp", ValueType::kDouble, 1, SignalKind::kState, 1, {0});
    StartDaemon("reload", {pos, sp});
  }
  // One frame from b, frame seq `seq`, carrying sp = v with value seq `value_seq`, under `hash`.
  void Send(uint32_t seq, uint32_t value_seq, double v, uint32_t hash) {
    std::vector<uint8_t> buf(wire::kMaxFrameSize);
    wire::FrameWriter w(buf.data(), buf.size());
    wire::FrameHeader h = PeerFrameHeader(seq, platform::MonotonicNs());
    h.config_hash = hash;
    w.Begin(h);
    ASSERT_TRUE(w.Add(kSp, static_cast<uint8_t>(ValueType::kDouble), 0, 1, value_seq, h.send_time_ns, &v, 8));
    const size_t len = w.Finish();
    ASSERT_EQ(sendto(tx_, buf.data(), len, 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(len));
    ++sent_;
  }
  uint64_t Counter(store::DaemonCounter c) { return daemon_.segment().header()->daemon_counters[c].load(); }
  void WaitHandled() {
    for (int i = 0; i < 400; ++i) {
      if (Counter(store::kFramesRx) + Counter(store::kFramesWrongHash) >= sent_) return;
      usleep(2000);
    }
    FAIL() << "daemon did not handle " << sent_ << " frames";
  }
  double State(uint64_t* value_seq) {
    double v = 0;
    store::SlotMeta m = {};
    if (store::StateRead(daemon_.segment().state(kSp), &v, &m) != store::StoreResult::kOk) m.value_seq = 0;
    *value_seq = m.value_seq;
    return v;
  }
  // As main() does: I/O threads stopped, Reconfigure, started again.
  void Reload(const SystemConfig& next) {
    daemon_.RequestStop();
    rx_.join();
    std::string err;
    ASSERT_EQ(daemon_.Reconfigure(next, 0, &err), 0) << err;
    rx_ = std::thread([this] { daemon_.RunRx(); });
  }

  // The send thread too, for the tests of the send side.
  void StartTx() { tx_thread_ = std::thread([this] { daemon_.RunTx(); }); }
  void StopBoth() {
    daemon_.RequestStop();
    rx_.join();
    if (tx_thread_.joinable()) tx_thread_.join();
  }
  void TearDown() override {
    if (tx_thread_.joinable()) StopBoth();
    testing::ReceivingDaemonTest::TearDown();
  }
  // An application's write of pos (what ccomm_write does: the value, its dirty bit, the doorbell).
  void WritePos(double v) {
    const uint64_t now = platform::MonotonicNs();
    ASSERT_EQ(store::StateWrite(daemon_.segment().state(kPos), &v, 0, now, now), store::StoreResult::kOk);
    daemon_.segment().MarkDirty(kPos);
    daemon_.segment().header()->tx_doorbell.fetch_add(1);
    platform::FutexWake(&daemon_.segment().header()->tx_doorbell, 1);
  }
  // An application's write of pos stopped where its writer has filled the cell's inline
  // copy but not yet raised `latest` (StateWrite, state_slot.h: a writer descheduled there);
  // EndWritePos finishes it. Returns the ticket.
  uint64_t BeginWritePos(double v) {
    const store::StateView sv = daemon_.segment().state(kPos);
    const uint64_t t = sv.cell->next_ticket.fetch_add(1);
    const uint64_t now = platform::MonotonicNs();
    const store::SlotMeta meta{t + 1, now, now};
    EXPECT_TRUE(store::ClaimCopy(sv.slot(t), t));
    store::PublishSlot(sv.slot(t), t, sv.value_bytes, &v, meta);
    EXPECT_TRUE(store::ClaimInline(sv, t));
    store::FillInline(sv, t, meta, &v);
    return t;
  }
  void EndWritePos(uint64_t t) {
    const store::StateView sv = daemon_.segment().state(kPos);
    store::PublishLatest(sv, t);
    store::ReleaseInline(sv, t);
    daemon_.segment().MarkDirty(kPos);
    daemon_.segment().header()->tx_doorbell.fetch_add(1);
    platform::FutexWake(&daemon_.segment().header()->tx_doorbell, 1);
  }
  // A reload that changes only a local setting (the segment stays), then both threads again.
  void ReconfigureLocalOnlyAndRun() {
    next_ = cfg_;
    next_.network.peer_timeout_ms = 900;
    std::string err;
    ASSERT_EQ(daemon_.Reconfigure(next_, 0, &err), 0) << err;
    ASSERT_TRUE(daemon_.adopted_segment());
    rx_ = std::thread([this] { daemon_.RunRx(); });
    StartTx();
  }
  bool WaitPosTx(uint64_t n) {
    const store::SignalStats& st = daemon_.segment().stats(kPos);
    for (int i = 0; i < 500 && st.tx.load() + st.coalesced.load() < n; ++i) usleep(2000);
    return st.tx.load() + st.coalesced.load() >= n;
  }

  SystemConfig next_;  // the reloaded configuration: lives as long as the daemon uses it
  std::thread tx_thread_;
  uint64_t sent_ = 0;
};

TEST_F(ReloadTest, LocalChangeKeepsTheSegmentAndWhatWasApplied) {
  Send(1, 7, 1.5, cfg_.hash);
  WaitHandled();
  const uint32_t generation = daemon_.segment().header()->generation.load();
  next_ = cfg_;
  next_.network.peer_timeout_ms = 900;  // local: not in the hash, not in the segment
  EXPECT_EQ(daemon_.ReloadRefusal(next_, 0), "");
  Reload(next_);
  EXPECT_TRUE(daemon_.adopted_segment());
  EXPECT_EQ(daemon_.segment().header()->generation.load(), generation + 1);
  // Value seq 7 again (a copy in flight across the reload): still known as applied.
  Send(2, 7, 2.5, cfg_.hash);
  WaitHandled();
  uint64_t seq = 0;
  EXPECT_EQ(State(&seq), 1.5);
  EXPECT_EQ(seq, 7u);
  EXPECT_EQ(daemon_.segment().stats(kSp).rx.load(), 1u);
  Send(3, 8, 3.5, cfg_.hash);
  WaitHandled();
  EXPECT_EQ(State(&seq), 3.5);
  EXPECT_EQ(seq, 8u);
  EXPECT_EQ(daemon_.segment().peer(1).frames_lost.load(), 0u);  // frames 1, 2, 3: none missing
  EXPECT_EQ(daemon_.segment().stats(kSp).lost.load(), 0u);
}

// Values an application writes while the reload has the send thread stopped still leave
// when it runs again (the cell's slots hold them: CatchUp), none vanishes uncounted.
TEST_F(ReloadTest, ValuesWrittenDuringTheReloadStillLeave) {
  StartTx();
  WritePos(1.0);
  ASSERT_TRUE(WaitPosTx(1));
  StopBoth();
  WritePos(2.0);
  WritePos(3.0);
  WritePos(4.0);
  ReconfigureLocalOnlyAndRun();
  const store::SignalStats& st = daemon_.segment().stats(kPos);
  ASSERT_TRUE(WaitPosTx(4)) << "tx " << st.tx.load() << " coalesced " << st.coalesced.load();
  EXPECT_EQ(st.tx.load(), 4u);  // 1 before; 2, 3 (caught up) and 4 after
  EXPECT_EQ(st.coalesced.load(), 0u);
}

// The send thread can take a value from the inline copy before its writer raised
// `latest` (state_slot.h): it is sent then, and `forwarded` stays one behind. When the
// writer publishes, the next round (here the first of the new send thread after a reload,
// which keeps each state's last value sent) finds that value again: it must not leave a
// second time (found in the fresh-clone run under ASan: tx 2677 for 2676 writes).
// Checked before the round's cut (send_catch_up.cpp) sent a state behind its writer only up
// to `latest`: without SendPath's "sent already" test this sent value 2 twice (tx 4, not 3).
// Now 2 is not taken before it is published; the "sent already" test stays as the guard.
TEST_F(ReloadTest, AValueTakenBeforeItsWriterPublishedLeavesOnceAcrossTheReload) {
  WritePos(1.0);                          // published; its dirty bit wakes the send thread
  const uint64_t t = BeginWritePos(2.0);  // the next value, in the inline copy only
  StartTx();  // its read finds 2 (inline), two after the last sent: the round's cut (send_catch_up.cpp) sends 1
  ASSERT_TRUE(WaitPosTx(1));
  usleep(20 * 1000);
  EXPECT_EQ(daemon_.segment().stats(kPos).tx.load(), 1u);  // 2 leaves once published, not before
  StopBoth();
  EndWritePos(t);  // the writer goes on while the threads are stopped
  ReconfigureLocalOnlyAndRun();
  // Its first round (EndWritePos's dirty bit), done once it sleeps.
  for (int i = 0; i < 500 && !daemon_.segment().header()->tx_sleeping.load(); ++i) usleep(2000);
  ASSERT_TRUE(daemon_.segment().header()->tx_sleeping.load());
  WritePos(3.0);
  const store::SignalStats& st = daemon_.segment().stats(kPos);
  ASSERT_TRUE(WaitPosTx(3)) << "tx " << st.tx.load() << " coalesced " << st.coalesced.load();
  usleep(20 * 1000);  // a duplicate would be counted by now (the send thread woke for 3)
  EXPECT_EQ(st.tx.load(), 3u);
  EXPECT_EQ(st.coalesced.load(), 0u);
}

TEST_F(ReloadTest, SignalChangeReplacesTheSegmentAndRefusesTheOldConfiguration) {
  Send(1, 7, 1.5, cfg_.hash);
  WaitHandled();
  store::Segment app;  // an application attached to the old segment
  ASSERT_EQ(app.Open(store::SegmentName("a")), 0);
  next_ = cfg_;
  next_.signals.push_back(testing::MakeSignal("z", ValueType::kDouble, 1, SignalKind::kState, 1, {0}));
  next_.hash = cfg_.hash + 1;  // what the parser's hash does when a signal is added
  EXPECT_EQ(daemon_.ReloadRefusal(next_, 0), "");
  Reload(next_);
  sent_ = 0;  // the counters are the new segment's
  EXPECT_FALSE(daemon_.adopted_segment());
  EXPECT_EQ(app.header()->state.load(), store::kRetired);
  EXPECT_EQ(daemon_.segment().signal_count(), 3u);
  // A board still on the old file: refused, nothing of it in the new segment.
  Send(2, 8, 2.5, cfg_.hash);
  WaitHandled();
  EXPECT_EQ(Counter(store::kFramesWrongHash), 1u);
  uint64_t seq = 0;
  State(&seq);
  EXPECT_EQ(seq, 0u);
  // One on the new file: applied.
  Send(3, 9, 3.5, next_.hash);
  WaitHandled();
  EXPECT_EQ(State(&seq), 3.5);
  EXPECT_EQ(seq, 9u);
}

TEST_F(ReloadTest, ChangeOfWhatTheSocketWasOpenedFromIsRefused) {
  next_ = cfg_;
  next_.path = "signals.xml";
  next_.nodes[0].line = 4;
  next_.nodes[0].ip = "127.0.0.99";
  next_.network.udp_port = static_cast<uint16_t>(cfg_.network.udp_port + 1);
  const std::string why = daemon_.ReloadRefusal(next_, 0);
  EXPECT_NE(why.find("signals.xml:4: error: node 'a': ip (" + cfg_.nodes[0].ip + " -> 127.0.0.99) cannot change "
                     "on a reload"), std::string::npos) << why;
  EXPECT_NE(why.find("signals.xml: error: <network> udp_port"), std::string::npos) << why;
}

}  // namespace
}  // namespace ccomm
