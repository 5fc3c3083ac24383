// SPDX-License-Identifier: Apache-2.0
// Large values through a real Daemon over loopback UDP (send_path.cpp, receive_path.cpp): fragments
// reassembled into one store write, a lost fragment loses exactly that value (counted),
// the last whole value stays readable with its own seq and source time, and every kind of
// bad fragment input is refused and counted without anything half-visible.
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

constexpr uint16_t kBigId = 1, kSmallId = 2, kPeriodicId = 3;
constexpr uint32_t kElems = 16384;  // uint32[16384]: 64 KiB
constexpr uint8_t kU32 = static_cast<uint8_t>(ValueType::kUint32);
using Frame = std::vector<uint8_t>;

struct FrameOpts {
  uint16_t sender = 1;
  uint16_t dest = 0;
  uint32_t hash_xor = 0;
  uint16_t signal = kBigId;
};

class LargeValuesTest : public testing::ReceivingDaemonTest {
 protected:
  void SetUp() override {
    // Node a (0) is the daemon under test; b (1) produces "big" and "small".
    auto pos = testing::MakeSignal("pos", ValueType::kDouble, 1, SignalKind::kState, 0, {1});
    auto big = testing::MakeSignal("big", ValueType::kUint32, kElems, SignalKind::kState, 1, {0});
    auto small = testing::MakeSignal("small", ValueType::kUint32, 4, SignalKind::kState, 1, {0});
    auto periodic = testing::MakeSignal("bigp", ValueType::kUint32, kElems, SignalKind::kState, 1, {0});
    periodic.period_us = 10000;
    StartDaemon("large", {pos, big, small, periodic});
  }

  // The fragment frames of value `value_seq` (all elements = fill), as ccommd splits it.
  std::vector<Frame> Fragments(uint32_t value_seq, uint32_t fill, uint64_t source_ns, FrameOpts o = FrameOpts()) {
    std::vector<uint32_t> v(kElems, fill);
    std::vector<Frame> out;
    const size_t part = wire::FrameWriter::MaxFragmentPart(false);
    for (size_t off = 0; off < kElems * 4; off += part) {
      Frame f(wire::kMaxFrameSize);
      wire::FrameWriter w(f.data(), f.size());
      wire::FrameHeader h;
      h.sender = o.sender;
      h.dest = o.dest;
      h.config_hash = cfg_.hash ^ o.hash_xor;
      h.seq = 0;  // set by Send
      w.Begin(h);
      EXPECT_TRUE(w.AddFragment(o.signal, kU32, 0, static_cast<uint16_t>(kElems), value_seq, source_ns,
                                static_cast<uint32_t>(off), reinterpret_cast<uint8_t*>(v.data()) + off,
                                std::min(part, kElems * 4 - off)));
      f.resize(w.Finish());
      out.push_back(f);
    }
    return out;
  }
  // Sends with the next frame seq and send time of b's stream to `dest`.
  void Send(Frame f) {
    const uint32_t seq = htonl(frame_seq_++);
    memcpy(f.data() + 12, &seq, 4);
    const uint64_t t = platform::MonotonicNs();
    for (int i = 0; i < 8; ++i) f[16 + i] = static_cast<uint8_t>(t >> (56 - 8 * i));
    ASSERT_EQ(sendto(tx_, f.data(), f.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(f.size()));
    ++sent_;
    WaitHandled();  // one at a time: the socket buffer never overflows, order is kept
  }
  void SendAll(const std::vector<Frame>& fs) {
    for (const Frame& f : fs) Send(f);
  }
  uint64_t Counter(store::DaemonCounter c) { return daemon_.segment().header()->daemon_counters[c].load(); }
  void WaitHandled() {
    for (int i = 0; i < 2000; ++i) {
      uint64_t t = Counter(store::kFramesRx) + Counter(store::kFramesUnknownSender) +
                   Counter(store::kFramesWrongSource) + Counter(store::kFramesBad) +
                   Counter(store::kFramesWrongHash) + Counter(store::kFramesNotForUs);
      if (t >= sent_) return;
      usleep(200);
    }
    FAIL() << "daemon did not handle " << sent_ << " frames";
  }
  const store::SignalStats& Stats(uint32_t id) { return daemon_.segment().stats(id); }
  // The stored value: whole (every element equal) and its fill, seq and source time.
  uint32_t Read(uint64_t* value_seq, uint64_t* source_ns) {
    std::vector<uint32_t> v(kElems);
    store::SlotMeta m;
    EXPECT_EQ(store::StateRead(daemon_.segment().state(kBigId), v.data(), &m), store::StoreResult::kOk);
    for (uint32_t i = 1; i < kElems; ++i) {
      if (v[i] != v[0]) {
        ADD_FAILURE() << "torn value: element " << i << " is " << v[i] << ", element 0 is " << v[0];
        break;
      }
    }
    *value_seq = m.value_seq;
    *source_ns = m.source_time_ns;
    return v[0];
  }

  uint32_t frame_seq_ = 0;
  uint64_t sent_ = 0;
};

TEST_F(LargeValuesTest, LostFragmentLosesExactlyThatValue) {
  SendAll(Fragments(1, 101, 1000));
  uint64_t seq = 0, src = 0;
  EXPECT_EQ(Read(&seq, &src), 101u);
  EXPECT_EQ(src, 1000u);
  auto two = Fragments(2, 102, 2000);
  two.erase(two.begin() + 30);  // one fragment lost on the way
  SendAll(two);
  EXPECT_EQ(Read(&seq, &src), 101u) << "the last whole value stays, with its own source time";
  EXPECT_EQ(src, 1000u);
  EXPECT_EQ(Stats(kBigId).values_incomplete.load(), 1u);
  auto three = Fragments(3, 103, 3000);
  three.pop_back();  // its last fragment lost: noticed when value 4 begins
  SendAll(three);
  SendAll(Fragments(4, 104, 4000));
  EXPECT_EQ(Read(&seq, &src), 104u);
  EXPECT_EQ(src, 4000u);
  EXPECT_EQ(Stats(kBigId).rx.load(), 2u);
  EXPECT_EQ(Stats(kBigId).lost.load(), 2u) << "values 2 and 3, once each";
  EXPECT_EQ(Stats(kBigId).values_incomplete.load(), 2u);
  EXPECT_EQ(Stats(kBigId).fragments_refused.load(), 0u) << "losses are not bad input";
  EXPECT_EQ(daemon_.segment().peer(1).frames_lost.load(), 0u) << "the test dropped fragments before numbering";
}

TEST_F(LargeValuesTest, PeriodicResendsAreNeitherRefusedNorNew) {
  FrameOpts p;
  p.signal = kPeriodicId;
  auto v = Fragments(1, 5, 1000, p);
  SendAll(v);
  SendAll(v);  // the next period: the same value
  auto cut = v;
  cut.resize(20);
  SendAll(cut);  // a period that lost its tail
  SendAll(v);
  EXPECT_EQ(Stats(kPeriodicId).rx.load(), 1u) << "one value, stored once";
  EXPECT_EQ(Stats(kPeriodicId).fragments_refused.load(), 0u);
  EXPECT_EQ(Stats(kPeriodicId).lost.load(), 0u);
  SendAll(Fragments(2, 6, 2000, p));
  EXPECT_EQ(Stats(kPeriodicId).rx.load(), 2u);
}

TEST_F(LargeValuesTest, BadFragmentsAreRefusedCountedAndNeverVisible) {
  SendAll(Fragments(1, 7, 1000));
  auto v = Fragments(2, 8, 2000);
  // Out of order: 5 before 4. The value is abandoned at 5 (a gap), 4 then is a part of a
  // lost value; nothing of value 2 is ever stored.
  for (size_t i = 0; i < 4; ++i) Send(v[i]);
  Send(v[5]);
  Send(v[4]);
  for (size_t i = 6; i < v.size(); ++i) Send(v[i]);
  uint64_t seq = 0, src = 0;
  EXPECT_EQ(Read(&seq, &src), 7u);
  EXPECT_EQ(Stats(kBigId).values_incomplete.load(), 1u);

  // Duplicated and overlapping fragments of value 3: refused, value 3 still completes.
  auto w = Fragments(3, 9, 3000);
  for (size_t i = 0; i < 10; ++i) Send(w[i]);
  Send(w[9]);
  Send(w[2]);
  Frame overlap = w[10];
  const uint32_t off = htonl(10 * 1408 - 8);  // starts 8 bytes inside fragment 9
  memcpy(overlap.data() + wire::kHeaderSize + wire::kEntryHeaderSize + 4, &off, 4);
  Send(overlap);
  EXPECT_EQ(Read(&seq, &src), 7u) << "nothing half-visible";
  for (size_t i = 10; i < w.size(); ++i) Send(w[i]);
  EXPECT_EQ(Read(&seq, &src), 9u);
  EXPECT_EQ(Stats(kBigId).fragments_refused.load(), 3u);

  // Oversized total: the decoder refuses the frame (total != count x 4).
  Frame big = Fragments(4, 10, 4000)[0];
  const uint32_t total = htonl(kElems * 4 + 4);
  memcpy(big.data() + wire::kHeaderSize + wire::kEntryHeaderSize, &total, 4);
  const uint64_t bad_before = Counter(store::kFramesBad);
  Send(big);
  EXPECT_EQ(Counter(store::kFramesBad), bad_before + 1);

  // A fragment entry for a signal that travels whole (4 x uint32 fits a frame).
  {
    Frame f(wire::kMaxFrameSize);
    wire::FrameWriter wr(f.data(), f.size());
    wire::FrameHeader h;
    h.sender = 1;
    h.config_hash = cfg_.hash;
    wr.Begin(h);
    uint32_t part[2] = {1, 2};
    ASSERT_TRUE(wr.AddFragment(kSmallId, kU32, 0, 4, 1, 1, 0, part, 8));
    f.resize(wr.Finish());
    const uint64_t wrong_before = Counter(store::kEntriesWrongType);
    Send(f);
    EXPECT_EQ(Counter(store::kEntriesWrongType), wrong_before + 1);
    EXPECT_EQ(Stats(kSmallId).fragments_refused.load(), 1u);
    EXPECT_EQ(Stats(kSmallId).rx.load(), 0u);
  }

  // From an unknown sender, and multicast (dest all) frames from a node with another
  // config hash: dropped before any entry is looked at.
  FrameOpts stranger;
  stranger.sender = 9;
  const uint64_t unknown_before = Counter(store::kFramesUnknownSender);
  SendAll(Fragments(5, 11, 5000, stranger));
  EXPECT_EQ(Counter(store::kFramesUnknownSender), unknown_before + 47);
  FrameOpts other_hash;
  other_hash.dest = wire::kDestAll;
  other_hash.hash_xor = 0x5a5a;
  const uint64_t hash_before = Counter(store::kFramesWrongHash);
  SendAll(Fragments(5, 11, 5000, other_hash));
  EXPECT_EQ(Counter(store::kFramesWrongHash), hash_before + 47);

  // Through all of it the last whole value stayed readable, whole, with its own seq and
  // source time; then the next good value goes through.
  EXPECT_EQ(Read(&seq, &src), 9u);
  EXPECT_EQ(src, 3000u);
  const uint64_t seq3 = seq;
  SendAll(Fragments(6, 12, 6000));
  EXPECT_EQ(Read(&seq, &src), 12u);
  EXPECT_EQ(seq, seq3 + 3) << "values 4 and 5 never arrived from b";
  EXPECT_EQ(Stats(kBigId).rx.load(), 3u);
  EXPECT_EQ(Stats(kBigId).lost.load(), 1u + 2u) << "value 2 (out of order), 4 and 5";
}

}  // namespace
}  // namespace ccomm
