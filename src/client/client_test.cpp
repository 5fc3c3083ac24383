// SPDX-License-Identifier: Apache-2.0
// The C and C++ APIs over a segment created in-process (no daemon needed).
#include "ccomm/ccomm.h"
#include "ccomm/ccomm.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "common/platform.h"
#include "daemon/engine/segment_builder.h"
#include "store/reclaim.h"
#include "store/segment.h"
#include "store/view.h"
#include "testing/test_config.h"

namespace ccomm {
namespace {

using testing::MakeSignal;
using testing::TwoNodeConfig;

class ClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("CCOMM_SHM_PREFIX", testing::UniquePrefix("client").c_str(), 1);
    std::vector<SignalConfig> signals = testing::PosAndSetpoint();
    SignalConfig& sp = signals[1];
    sp.stale_after_ms = 20;
    sp.has_safe_value = true;
    double safe = -1.0;
    sp.safe_value.resize(8);
    memcpy(sp.safe_value.data(), &safe, 8);
    signals.push_back(MakeSignal("arr", ValueType::kInt32, 3, SignalKind::kState, 0, {}));
    signals.push_back(MakeSignal("estop", ValueType::kBool, 1, SignalKind::kEvent, 0, {}));
    signals.back().queue_depth = 8;
    signals.push_back(MakeSignal("local", ValueType::kFloat, 1, SignalKind::kState, 0, {0}));
    signals.back().stale_after_ms = 1000;
    cfg_ = TwoNodeConfig(signals);
    std::string err;
    bool adopted;
    ASSERT_EQ(CreateOrAdoptSegment(&seg_a_, cfg_, 0, store::SegmentName("a"), -1, &adopted, &err), 0) << err;
    ASSERT_EQ(CreateOrAdoptSegment(&seg_b_, cfg_, 1, store::SegmentName("b"), -1, &adopted, &err), 0) << err;
  }
  void TearDown() override {
    platform::ShmUnlink(store::SegmentName("a").c_str());
    platform::ShmUnlink(store::SegmentName("b").c_str());
  }
  SystemConfig cfg_;
  store::Segment seg_a_, seg_b_;
};

// The application's real-time set-up and periodic sleep: the platform layer's, through
// the C API (no handle needed); a part that cannot be done is said per part.
TEST(ClientRealtime, SetUpSaysEachPartAndSleepUntilKeepsItsDeadline) {
  int32_t err[3] = {7, 7, 7};
  EXPECT_EQ(ccomm_realtime_setup(-1, 0, 0, err), 0);  // nothing asked: nothing fails
  EXPECT_EQ(err[0], 0);
  EXPECT_EQ(err[1], 0);
  EXPECT_EQ(err[2], 0);
  EXPECT_EQ(ccomm_realtime_setup(-1, 0, 0, nullptr), 0);
  // A CPU this machine does not have: that part fails, the others are untouched.
  EXPECT_EQ(ccomm_realtime_setup(1000, 0, 0, err), CCOMM_E_SYS);
  EXPECT_LT(err[0], 0);
  EXPECT_EQ(err[1], 0);
  EXPECT_EQ(err[2], 0);
  // The CPU this thread runs on: pinning to it is allowed without privilege.
  const int cpu = sched_getcpu();
  ASSERT_GE(cpu, 0);
  EXPECT_EQ(ccomm_realtime_setup(cpu, 0, 0, err), 0);
  EXPECT_EQ(err[0], 0);

  EXPECT_EQ(ccomm_sleep_until(-1), CCOMM_E_INVAL);
  const int64_t t0 = ccomm_now();
  EXPECT_EQ(ccomm_sleep_until(t0 - 1000000), 0);  // past: at once
  const int64_t deadline = ccomm_now() + 20000000;
  EXPECT_EQ(ccomm_sleep_until(deadline), 0);
  EXPECT_GE(ccomm_now(), deadline);
  EXPECT_EQ(ccomm::Client::sleep_until(ccomm_now() + 1000000), 0);
}

TEST_F(ClientTest, OpenFindDescribe) {
  ccomm_client* c = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &c), 0);
  EXPECT_STREQ(ccomm_node_name(c), "a");
  EXPECT_EQ(ccomm_signal_count(c), 5);
  ccomm_signal s = ccomm_find(c, "arr");
  ASSERT_EQ(s, 2);
  ccomm_signal_desc d;
  ASSERT_EQ(ccomm_describe(c, s, &d), 0);
  EXPECT_STREQ(d.name, "arr");
  EXPECT_EQ(d.type, CCOMM_INT32);
  EXPECT_EQ(d.count, 3u);
  EXPECT_EQ(d.value_bytes, 12u);
  EXPECT_EQ(d.produced_here, 1);
  EXPECT_STREQ(d.producer, "a");
  EXPECT_EQ(d.forwarded, 0);  // no other node consumes it: ccommd never sends it
  ASSERT_EQ(ccomm_describe(c, ccomm_find(c, "pos"), &d), 0);
  EXPECT_EQ(d.forwarded, 1);  // consumed by b
  ASSERT_EQ(ccomm_describe(c, ccomm_find(c, "local"), &d), 0);
  EXPECT_EQ(d.forwarded, 0);  // consumed by a, its producer, only
  EXPECT_EQ(ccomm_find(c, "missing"), CCOMM_E_NOENT);
  ccomm_close(c);
  ccomm_client* none = nullptr;
  EXPECT_EQ(ccomm_open("nosuchnode", 0, &none), CCOMM_E_NOENT);
  EXPECT_EQ(none, nullptr);
}

TEST_F(ClientTest, ApiMisuseIsRejectedNotFatal) {
  ccomm_client* c = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &c), 0);
  double v = 0;
  EXPECT_EQ(ccomm_read(nullptr, 0, &v, 8, nullptr), CCOMM_E_INVAL);
  EXPECT_EQ(ccomm_read(c, 99, &v, 8, nullptr), CCOMM_E_INVAL);
  EXPECT_EQ(ccomm_read(c, -1, &v, 8, nullptr), CCOMM_E_INVAL);
  EXPECT_EQ(ccomm_read(c, 0, &v, 4, nullptr), CCOMM_E_TYPE);
  EXPECT_EQ(ccomm_write(c, 0, nullptr, 8), CCOMM_E_INVAL);
  EXPECT_EQ(ccomm_write(c, 1, &v, 8), CCOMM_E_PERM);  // "sp" is produced by b
  int32_t i = 0;
  EXPECT_EQ(ccomm_read_int32(c, 0, &i, nullptr), CCOMM_E_TYPE);
  EXPECT_EQ(ccomm_write_float(c, 0, 1.0f), CCOMM_E_TYPE);
  EXPECT_STRNE(ccomm_strerror(CCOMM_E_PERM), "unknown code");
  ccomm_close(c);
  ccomm_close(nullptr);  // harmless
}

TEST_F(ClientTest, StateReadsSayFreshStaleNeverWithSafeValue) {
  ccomm_client *a = nullptr, *b = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &a), 0);
  ASSERT_EQ(ccomm_open("b", 0, &b), 0);
  ccomm_signal sp = ccomm_find(a, "sp");
  double v = 123;
  ccomm_info info;
  EXPECT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_NEVER);
  EXPECT_EQ(info.status, CCOMM_NEVER);
  EXPECT_EQ(v, -1.0);  // the safe value
  EXPECT_TRUE(info.flags & CCOMM_INFO_SAFE_VALUE);
  EXPECT_EQ(info.age_ns, -1);
  // "sp" on node a is written by ccommd from the network; simulate that delivery.
  double in = 7.5;
  ASSERT_EQ(store::StateWrite(seg_a_.state(1), &in, 42, 5, platform::MonotonicNs()), store::StoreResult::kOk);
  EXPECT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_FRESH);
  EXPECT_EQ(v, 7.5);
  EXPECT_EQ(info.seq, 42u);
  EXPECT_EQ(info.source_time_ns, 5u);
  EXPECT_GE(info.age_ns, 0);
  EXPECT_EQ(info.flags, 0u);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_STALE);
  EXPECT_EQ(v, -1.0);
  EXPECT_GT(info.age_ns, 20 * 1000000);
  ccomm_close(a);
  ccomm_close(b);
}

// ccomm_read_double's cache (ReadState8): an unchanged cell is answered from the handle's
// last copy; a new value is taken from the inline copy, or from the slot when the inline
// copy is being rewritten; a damaged copy is refused, counted, never returned, and is not
// kept as the cached value (the next read checks the cell again).
TEST_F(ClientTest, DoubleReadCacheFollowsTheCellAndRefusesDamage) {
  ccomm_client* a = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &a), 0);
  const ccomm_signal sp = ccomm_find(a, "pos");  // never stale
  ASSERT_EQ(sp, 0);
  const store::StateView sv = seg_a_.state(0);
  store::SignalStats& stats = seg_a_.stats(0);
  const uint64_t corrupt0 = stats.corrupt.load();
  double in = 1.5, v = 0;
  ccomm_info info;
  const uint64_t now = platform::MonotonicNs();
  ASSERT_EQ(store::StateWrite(sv, &in, 10, 1, now), store::StoreResult::kOk);
  ASSERT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_FRESH);
  EXPECT_EQ(v, 1.5);
  EXPECT_EQ(info.seq, 10u);
  v = 0;
  ASSERT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_FRESH);  // unchanged: the cached copy
  EXPECT_EQ(v, 1.5);
  EXPECT_EQ(info.seq, 10u);
  EXPECT_EQ(info.source_time_ns, 1u);

  // A stray write into the inline copy's value, its sequence word left plausible.
  in = 2.5;
  ASSERT_EQ(store::StateWrite(sv, &in, 11, 2, now), store::StoreResult::kOk);
  sv.cell->inline_value[0].fetch_xor(1);
  v = 0;
  EXPECT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_E_CORRUPT);
  EXPECT_EQ(v, 0.0);  // nothing of the damaged copy returned
  EXPECT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_E_CORRUPT);  // not cached
  EXPECT_EQ(v, 0.0);
  EXPECT_EQ(stats.corrupt.load(), corrupt0 + 2);

  // The next value heals it; then the inline copy is marked as being rewritten: the read
  // falls back to the slot of `latest`.
  in = 3.5;
  ASSERT_EQ(store::StateWrite(sv, &in, 12, 3, now), store::StoreResult::kOk);
  ASSERT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_FRESH);
  EXPECT_EQ(v, 3.5);
  EXPECT_EQ(info.seq, 12u);
  in = 4.5;
  ASSERT_EQ(store::StateWrite(sv, &in, 13, 4, now), store::StoreResult::kOk);
  sv.cell->inline_seq.fetch_or(1);
  ASSERT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_FRESH);
  EXPECT_EQ(v, 4.5);
  EXPECT_EQ(info.seq, 13u);
  EXPECT_EQ(info.source_time_ns, 4u);
  v = 0;
  ASSERT_EQ(ccomm_read_double(a, sp, &v, &info), CCOMM_FRESH);  // cached from the slot read
  EXPECT_EQ(v, 4.5);
  EXPECT_EQ(stats.corrupt.load(), corrupt0 + 2);
  ccomm_close(a);
}

TEST_F(ClientTest, TwoAppsOnOneNodeThroughSharedMemory) {
  ccomm::Client writer("a"), reader("a");
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(reader.ok());
  auto w = writer.signal<float>("local");
  auto r = reader.signal<float>("local");
  ASSERT_TRUE(w.valid());
  EXPECT_TRUE(r.read().never());
  ASSERT_EQ(w.write(3.25f), 0);
  auto got = r.read();
  EXPECT_TRUE(got.fresh());
  EXPECT_EQ(got.value, 3.25f);
  EXPECT_EQ(got.info.seq, 1u);
  auto arr_w = writer.signal<std::array<int32_t, 3>>("arr");
  auto arr_r = reader.signal<std::array<int32_t, 3>>("arr");
  ASSERT_TRUE(arr_w.valid());
  ASSERT_EQ(arr_w.write({1, -2, 3}), 0);
  auto ga = arr_r.read();
  EXPECT_EQ(ga.value[1], -2);
  // Wrong type / count is refused at lookup.
  EXPECT_FALSE(reader.signal<double>("local").valid());
  EXPECT_EQ(reader.error(), CCOMM_E_TYPE);
  EXPECT_FALSE((reader.signal<std::array<int32_t, 2>>("arr").valid()));
}

TEST_F(ClientTest, CppCoversBatchStatsAndIntrospection) {
  ccomm::Client batch("a", CCOMM_OPEN_BATCH), reader("a");
  ASSERT_TRUE(batch.ok());
  auto w = batch.signal<float>("local");
  auto r = reader.signal<float>("local");
  ASSERT_EQ(w.write(1.5f), 0);
  EXPECT_TRUE(r.read().never());  // held in the batch handle until the flush
  ASSERT_EQ(batch.flush(), 0);
  EXPECT_EQ(r.read().value, 1.5f);
  ccomm_signal_stats st;
  ASSERT_EQ(w.stats(st), 0);
  EXPECT_EQ(st.writes, 1u);
  EXPECT_EQ(batch.signal_count(), 5);
  ccomm_signal_desc d;
  ASSERT_EQ(batch.describe(w.id(), d), 0);
  EXPECT_STREQ(d.name, "local");
  EXPECT_EQ(batch.node_count(), 2);
  ccomm_peer_stats ps;
  ASSERT_EQ(batch.peer_stats(0, ps), 0);
  EXPECT_EQ(ps.is_self, 1);
  EXPECT_EQ(batch.peer_stats(5, ps), CCOMM_E_INVAL);
}

TEST_F(ClientTest, SizedCallsServeOlderAndNewerCallers) {
  ccomm_client* c = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &c), 0);
  const ccomm_signal s = ccomm_find(c, "local");
  ASSERT_EQ(ccomm_write_float(c, s, 2.0f), 0);
  // A newer program's bigger struct: this library's fields, zeros beyond.
  unsigned char big[sizeof(ccomm_signal_stats) + 16];
  memset(big, 0xff, sizeof big);
  ASSERT_EQ(ccomm_get_signal_stats_sized(c, s, reinterpret_cast<ccomm_signal_stats*>(big), sizeof big), 0);
  for (size_t i = sizeof(ccomm_signal_stats); i < sizeof big; ++i) EXPECT_EQ(big[i], 0) << i;
  ccomm_signal_stats now;
  memcpy(&now, big, sizeof now);
  EXPECT_EQ(now.writes, 1u);
  // Smaller than the struct these calls began with: refused, untouched.
  unsigned char small[88];
  memset(small, 0xff, sizeof small);
  EXPECT_EQ(ccomm_get_signal_stats_sized(c, s, reinterpret_cast<ccomm_signal_stats*>(small), sizeof small),
            CCOMM_E_INVAL);
  EXPECT_EQ(small[0], 0xff);
  // The plain symbol, as a program built against ccomm 0.1.0 calls it: that layout, 80
  // bytes (writes at 0, last_rx_age_ns at 64, stale at 72), nothing beyond.
  unsigned char old[96];
  memset(old, 0xff, sizeof old);
  ASSERT_EQ((ccomm_get_signal_stats)(c, s, reinterpret_cast<ccomm_signal_stats*>(old)), 0);
  uint64_t writes;
  int64_t age;
  int32_t stale;
  memcpy(&writes, old, 8);
  memcpy(&age, old + 64, 8);
  memcpy(&stale, old + 72, 4);
  EXPECT_EQ(writes, 1u);
  EXPECT_EQ(age, -1);
  EXPECT_EQ(stale, 0);
  for (size_t i = 80; i < sizeof old; ++i) EXPECT_EQ(old[i], 0xff) << i;
  ccomm_close(c);
}

TEST_F(ClientTest, EventsArriveOncePerReader) {
  ccomm::Client w("a"), r1("a"), r2("a");
  auto e = w.signal<bool>("estop");
  auto e1 = r1.signal<bool>("estop");
  auto e2 = r2.signal<bool>("estop");
  EXPECT_TRUE(e1.read().empty());
  ASSERT_EQ(e.write(true), 0);
  ASSERT_EQ(e.write(false), 0);
  for (auto* s : {&e1, &e2}) {
    auto x = s->read();
    EXPECT_TRUE(x.fresh());
    EXPECT_TRUE(x.value);
    x = s->read();
    EXPECT_TRUE(x.fresh());
    EXPECT_FALSE(x.value);
    EXPECT_TRUE(s->read().empty());
  }
  // Overrun of a local (not forwarded) ring is reported to the slow reader.
  for (int i = 0; i < 20; ++i) ASSERT_EQ(e.write(i & 1), 0);
  int n = 0;
  ccomm::Reading<bool> x;
  while ((x = e1.read()).fresh()) n++;
  EXPECT_EQ(n, 8);
  EXPECT_EQ(x.info.lost, 12u);
}

TEST_F(ClientTest, WaitWakesOnWriteAndTimesOut) {
  ccomm::Client w("a"), r("a");
  auto s = w.signal<float>("local");
  EXPECT_FALSE(r.wait(10));
  std::thread t([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    s.write(1.0f);
  });
  EXPECT_TRUE(r.wait(5000));
  t.join();
}

// A write that lands between a consumer's reads and its next ccomm_wait() is not
// missed (the wait returns at once), for states and events, with and without the
// doorbell; a wait reports each change once.
TEST_F(ClientTest, WaitNeverMissesAWriteBeforeTheCall) {
  for (uint32_t flags : {0u, unsigned{CCOMM_OPEN_NO_DOORBELL}}) {
    ccomm_client* w = nullptr;
    ASSERT_EQ(ccomm_open("a", flags, &w), 0);
    ccomm::Client r("a");
    ccomm_signal local = ccomm_find(w, "local"), ev = ccomm_find(w, "estop");
    EXPECT_FALSE(r.wait(0));  // nothing since the open
    ASSERT_EQ(ccomm_write_float(w, local, 2.0f), 0);
    EXPECT_TRUE(r.wait(0));
    EXPECT_FALSE(r.wait(0));  // already reported
    ASSERT_EQ(ccomm_write_bool(w, ev, 1), 0);
    EXPECT_TRUE(r.wait(1000));
    EXPECT_FALSE(r.wait(5));
    ccomm_close(w);
  }
}

// Three waiters and a writer: each waiter reads after every wake-up and must see the
// last value without ever timing out (a lost wake-up would leave it asleep).
TEST_F(ClientTest, WaitersSeeEveryWriteWithoutTimingOut) {
  ccomm::Client w("a");
  auto s = w.signal<float>("local");
  std::atomic<int> ready{0}, timeouts{0}, done{0};
  std::vector<std::thread> th;
  for (int k = 0; k < 3; ++k) {
    th.emplace_back([&] {
      ccomm::Client r("a");
      auto rs = r.signal<float>("local");
      ready++;
      for (;;) {
        if (rs.read().value == 199.0f) break;
        if (!r.wait(5000)) {
          timeouts++;
          break;
        }
      }
      done++;
    });
  }
  while (ready.load() < 3) std::this_thread::yield();
  for (int i = 0; i < 200; ++i) {
    ASSERT_EQ(s.write(static_cast<float>(i)), 0);
    if (i % 10 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  for (auto& t : th) t.join();
  EXPECT_EQ(timeouts.load(), 0);
  EXPECT_EQ(done.load(), 3);
  EXPECT_EQ(seg_a_.header()->rx_waiters.load(), 0u);
}

// ccomm_set_time: writes carry the cycle time, reads judge freshness and age against
// it (a value newer than the cycle time is fresh, age 0); 0 returns to the clock.
TEST_F(ClientTest, CycleTimeStampsWritesAndJudgesReads) {
  ccomm_client* w = nullptr;
  ccomm_client* r = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &w), 0);
  ASSERT_EQ(ccomm_open("a", 0, &r), 0);
  ccomm_signal local = ccomm_find(w, "local");  // stale_after_ms = 1000
  EXPECT_EQ(ccomm_set_time(nullptr, 1), CCOMM_E_INVAL);
  EXPECT_EQ(ccomm_set_time(w, -1), CCOMM_E_INVAL);
  const int64_t t0 = ccomm_now();
  ASSERT_EQ(ccomm_set_time(w, t0 - 5000000), 0);  // the writer's cycle began 5 ms ago
  ASSERT_EQ(ccomm_write_float(w, local, 1.5f), 0);
  float v = 0;
  ccomm_info info;
  ASSERT_EQ(ccomm_read_float(r, local, &v, &info), CCOMM_FRESH);  // per-call clock
  EXPECT_GE(info.age_ns, 5000000);
  EXPECT_EQ(info.source_time_ns, static_cast<uint64_t>(t0 - 5000000));
  ASSERT_EQ(ccomm_set_time(r, t0 - 6000000), 0);  // a cycle time before the write
  ASSERT_EQ(ccomm_read_float(r, local, &v, &info), CCOMM_FRESH);
  EXPECT_EQ(info.age_ns, 0);
  ASSERT_EQ(ccomm_set_time(r, t0 + 2000000000), 0);  // 2 s later: stale
  EXPECT_EQ(ccomm_read_float(r, local, &v, &info), CCOMM_STALE);
  EXPECT_EQ(info.age_ns, 2005000000);
  ASSERT_EQ(ccomm_set_time(r, 0), 0);
  EXPECT_EQ(ccomm_read_float(r, local, &v, &info), CCOMM_FRESH);
  ccomm_close(w);
  ccomm_close(r);
}

TEST_F(ClientTest, RetiredSegmentIsReported) {
  ccomm::Client c("a");
  auto s = c.signal<float>("local");
  seg_a_.header()->state.store(store::kRetired);
  EXPECT_EQ(s.read().status, CCOMM_E_RETIRED);
  EXPECT_EQ(s.write(1.0f), CCOMM_E_RETIRED);
}

// ccomm.hpp: error() says why "the open or the last signal() failed (0: it did not)", so a
// successful signal() after a failed one reads 0, not the earlier failure.
TEST_F(ClientTest, CppErrorIsClearedByASuccessfulSignal) {
  ccomm::Client c("a");
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c.error(), 0);
  EXPECT_FALSE(c.signal<double>("missing").valid());
  EXPECT_EQ(c.error(), CCOMM_E_NOENT);
  EXPECT_FALSE(c.signal<double>("arr").valid());
  EXPECT_EQ(c.error(), CCOMM_E_TYPE);
  EXPECT_TRUE((c.signal<std::array<int32_t, 3>>("arr").valid()));
  EXPECT_EQ(c.error(), 0);
}

// An application killed while it waits in ccomm_wait() leaves its wait registered: before
// the waiter entries, rx_waiters stayed raised for good, and every write on the node made a
// FUTEX_WAKE from then on (found by the syscalls step). ccommd's scan takes it back; a
// live waiter's wait is left alone.
TEST_F(ClientTest, WaitOfAProcessThatDiedWaitingIsTakenBack) {
  store::SegmentHeader* h = seg_a_.header();
  ASSERT_EQ(h->rx_waiters.load(), 0u);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ccomm_client* c = nullptr;
    if (ccomm_open("a", 0, &c) != 0) _exit(2);
    ccomm_wait(c, 0);  // "changed since the open"
    ccomm_wait(c, 60000);
    _exit(0);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (h->rx_waiters.load() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_EQ(h->rx_waiters.load(), 1u);
  EXPECT_EQ(store::ReclaimDeadWaiters(h), 0u);  // alive: nothing taken
  EXPECT_EQ(h->rx_waiters.load(), 1u);
  kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_EQ(h->rx_waiters.load(), 1u);  // what it left behind
  EXPECT_EQ(store::ReclaimDeadWaiters(h), 1u);
  EXPECT_EQ(h->rx_waiters.load(), 0u);
  for (const store::WaiterEntry& e : h->waiters) EXPECT_NE(e.pid.load(), static_cast<uint32_t>(child));
  // A waiter of this process (a thread) registers in its own entry and ends its wait itself.
  ccomm_client* c = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &c), 0);
  ccomm_wait(c, 0);
  EXPECT_EQ(ccomm_wait(c, 20), 0);  // nothing changed: timed out
  EXPECT_EQ(h->rx_waiters.load(), 0u);
  ccomm_close(c);
}

// A consumer asleep in ccomm_wait() when ccommd replaces the segment (new configuration)
// is woken and told CCOMM_E_RETIRED, as reads and writes are; before, nothing rang the
// old segment's doorbell again and it slept until its timeout (forever with -1).
TEST_F(ClientTest, WaitReturnsRetiredWhenTheSegmentIsReplaced) {
  ccomm_client* c = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &c), 0);
  ccomm_wait(c, 0);  // consume "changed since the open"
  std::atomic<int> result{1000};
  std::thread waiter([&] { result = ccomm_wait(c, 30000); });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (seg_a_.header()->rx_waiters.load() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_EQ(seg_a_.header()->rx_waiters.load(), 1u);
  SystemConfig changed = cfg_;
  changed.signals[2].count = 4;
  changed.hash += 1;
  store::Segment replacement;
  std::string err;
  bool adopted = true;
  ASSERT_EQ(CreateOrAdoptSegment(&replacement, changed, 0, store::SegmentName("a"), -1, &adopted, &err), 0) << err;
  EXPECT_FALSE(adopted);
  const auto retired_at = std::chrono::steady_clock::now();
  waiter.join();
  EXPECT_EQ(result.load(), CCOMM_E_RETIRED);
  EXPECT_LT(std::chrono::steady_clock::now() - retired_at, std::chrono::seconds(20));
  EXPECT_EQ(ccomm_wait(c, 0), CCOMM_E_RETIRED);
  EXPECT_EQ(ccomm_wait(c, -1), CCOMM_E_RETIRED);  // already retired: no sleep at all
  ccomm_close(c);
}

// ccommd descheduled in the middle of rewriting a node record (the seqlock odd for
// milliseconds, longer than the store's spinning reader tries) must not make a monitoring
// tool drop that node (CI: `ccomm stats --all --json` printed "nodes":[, with node 0
// missing); only a record that stays odd (writer stopped mid-write) is CCOMM_E_BUSY.
TEST_F(ClientTest, SystemViewWaitsOutAWriterDescheduledMidRewrite) {
  store::View writer;
  std::string err;
  ASSERT_EQ(writer.Create(store::View::NameFor("a"), 2, 5, 0, 100, -1, &err), 0) << err;
  writer.mutable_header()->state.store(store::kViewReady, std::memory_order_release);
  ccomm_client* c = nullptr;
  ASSERT_EQ(ccomm_open("a", 0, &c), 0);
  ccomm_view* v = nullptr;
  ASSERT_EQ(ccomm_view_open(c, &v), 0);
  writer.BeginWrite(1);
  std::thread finisher([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    writer.SetNodeWord(1, store::kVwUptimeNs, 7000000000ull);
    writer.EndWrite(1);
  });
  ccomm_view_node vn;
  EXPECT_EQ(ccomm_view_get_node(v, 1, &vn), 0);
  finisher.join();
  EXPECT_EQ(vn.uptime_ns, 7000000000ull);
  writer.BeginWrite(0);  // never ended
  EXPECT_EQ(ccomm_view_get_node(v, 0, &vn), CCOMM_E_BUSY);
  ccomm_view_signal vs;
  EXPECT_EQ(ccomm_view_get_signal(v, 0, 0, &vs), CCOMM_E_BUSY);
  writer.EndWrite(0);
  EXPECT_EQ(ccomm_view_get_node(v, 0, &vn), 0);
  ccomm_view_close(v);
  ccomm_close(c);
  platform::ShmUnlink(store::View::NameFor("a").c_str());
}

}  // namespace
}  // namespace ccomm
