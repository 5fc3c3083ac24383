// SPDX-License-Identifier: Apache-2.0
// Send on the cycle (send_cycle.h): the grid, the clock it is aligned on, the lead, the
// launch times and the launch decision, with made-up clocks.
#include "daemon/engine/send_cycle.h"

#include <gtest/gtest.h>

#include <cerrno>

namespace ccomm {
namespace {

constexpr uint64_t kUs = 1000, kMs = 1000000, kS = 1000000000;

SendCycleConfig Make(uint64_t cycle, uint64_t phase, uint64_t lead) {
  SendCycleConfig cfg;
  cfg.cycle_ns = cycle;
  cfg.phase_ns = phase;
  cfg.lead_ns = lead;
  return cfg;
}

// On CLOCK_MONOTONIC: instants at k * period + phase, the first one whose wake-up
// (instant - lead) is not in the past.
TEST(SendCycle, PhaseOnTheMonotonicGrid) {
  SendCycle c;
  c.Configure(Make(1 * kMs, 250 * kUs, 300 * kUs));
  c.SetClock(false, 0);
  EXPECT_EQ(c.clock(), CycleClock::kMonotonic);
  // now 10.000 ms: 10.250 - 0.300 = 9.950 < now, so 11.250
  EXPECT_EQ(c.Place(10 * kMs, 1 * kMs), 11 * kMs + 250 * kUs);
  // now 9.950 ms exactly: 10.250 is still reachable
  EXPECT_EQ(c.Place(9 * kMs + 950 * kUs, 1 * kMs), 10 * kMs + 250 * kUs);
  EXPECT_EQ(c.Place(9 * kMs + 950 * kUs + 1, 1 * kMs), 11 * kMs + 250 * kUs);
  // A 4 ms signal: instants 4k ms + 0.25 ms only.
  EXPECT_EQ(c.Place(10 * kMs, 4 * kMs), 12 * kMs + 250 * kUs);
  EXPECT_EQ(c.Place(12 * kMs, 4 * kMs), 16 * kMs + 250 * kUs);
  EXPECT_EQ(c.WakeAt(12 * kMs + 250 * kUs), 11 * kMs + 950 * kUs);
  // Near zero (a young monotonic clock): no wrap below zero.
  EXPECT_EQ(c.Place(0, 1 * kMs), 1 * kMs + 250 * kUs);
}

// Synced: the grid is CLOCK_TAI's. With TAI = mono + 5.0004 s, the TAI instants
// k ms + 250 us are mono (k ms + 250 us - 5.0004 s): mono ... .8500 ms.
TEST(SendCycle, AlignedOnTaiWhenSynced) {
  SendCycle c;
  c.Configure(Make(1 * kMs, 250 * kUs, 300 * kUs));
  const int64_t off = static_cast<int64_t>(5 * kS + 400 * kUs);
  const uint32_t g0 = c.generation();
  EXPECT_TRUE(c.SetClock(true, off));
  EXPECT_EQ(c.clock(), CycleClock::kTai);
  EXPECT_NE(c.generation(), g0);
  const uint64_t now = 100 * kMs;
  const uint64_t t = c.Place(now, 1 * kMs);
  EXPECT_EQ((t + static_cast<uint64_t>(off)) % kMs, 250 * kUs);  // on the TAI grid
  EXPECT_EQ(t, 100 * kMs + 850 * kUs);
  EXPECT_GE(t - 300 * kUs, now);
  EXPECT_LT(t - 300 * kUs, now + 1 * kMs);
  // The launch time is the instant on CLOCK_TAI.
  EXPECT_EQ(c.LaunchTai(t), t + static_cast<uint64_t>(off));
}

// Switching: synced -> lost goes back to the monotonic grid (and the generation tells
// the send thread to re-place); the TAI offset keeps following for launch times.
TEST(SendCycle, ClockSwitching) {
  SendCycle c;
  c.Configure(Make(2 * kMs, 0, 500 * kUs));
  const int64_t off = static_cast<int64_t>(37 * kS + 123 * kUs);
  EXPECT_FALSE(c.SetClock(false, off));  // already monotonic: no switch
  const uint32_t g1 = c.generation();
  EXPECT_EQ(c.Place(10 * kMs, 0), 12 * kMs);  // period 0: the cycle
  EXPECT_TRUE(c.SetClock(true, off));
  const uint32_t g2 = c.generation();
  EXPECT_NE(g2, g1);
  EXPECT_EQ((c.Place(10 * kMs, 0) + static_cast<uint64_t>(off)) % (2 * kMs), 0u);
  // Noise in reading the offset (under 10 us) neither switches nor re-places.
  EXPECT_FALSE(c.SetClock(true, off + 3000));
  EXPECT_EQ(c.generation(), g2);
  // A step of the clock while synced re-places (same clock, new grid).
  EXPECT_FALSE(c.SetClock(true, off + 50 * static_cast<int64_t>(kUs)));
  EXPECT_NE(c.generation(), g2);
  EXPECT_EQ((c.Place(10 * kMs, 0) + static_cast<uint64_t>(off) + 50 * kUs) % (2 * kMs), 0u);
  EXPECT_TRUE(c.SetClock(false, off));
  EXPECT_EQ(c.clock(), CycleClock::kMonotonic);
  EXPECT_EQ(c.Place(10 * kMs, 0), 12 * kMs);
  EXPECT_EQ(c.LaunchTai(12 * kMs), 12 * kMs + static_cast<uint64_t>(off));
}

// The lead: a longer lead moves the first reachable instant, never the grid.
TEST(SendCycle, LeadDecidesTheFirstReachableInstant) {
  SendCycle shortLead;
  shortLead.Configure(Make(1 * kMs, 100 * kUs, 50 * kUs));
  SendCycle longLead;
  longLead.Configure(Make(1 * kMs, 100 * kUs, 900 * kUs));
  shortLead.SetClock(false, 0);
  longLead.SetClock(false, 0);
  const uint64_t now = 20 * kMs;  // 20.100 is 100 us away
  EXPECT_EQ(shortLead.Place(now, 1 * kMs), 20 * kMs + 100 * kUs);
  EXPECT_EQ(longLead.Place(now, 1 * kMs), 21 * kMs + 100 * kUs);
  EXPECT_EQ(longLead.WakeAt(21 * kMs + 100 * kUs), 20 * kMs + 200 * kUs);
}

TEST(SendCycle, LaunchDecision) {
  SendCycleConfig cfg;
  TxtimeProbe ok;
  ok.platform = true;
  ok.etf = true;
  ok.etf_delta_ns = 200 * kUs;
  EXPECT_EQ(SendCycle::Decide(cfg, ok), LaunchMode::kOff);  // no cycle
  cfg.cycle_ns = 1 * kMs;
  cfg.lead_ns = 300 * kUs;
  EXPECT_EQ(SendCycle::Decide(cfg, ok), LaunchMode::kTxtime);
  TxtimeProbe p = ok;
  p.platform = false;
  EXPECT_EQ(SendCycle::Decide(cfg, p), LaunchMode::kSleepPlatform);
  p = ok;
  p.socket_error = EPERM;
  EXPECT_EQ(SendCycle::Decide(cfg, p), LaunchMode::kSleepRefused);
  p = ok;
  p.etf = false;
  EXPECT_EQ(SendCycle::Decide(cfg, p), LaunchMode::kSleepNoEtf);
  // ETF releases frames delta before their launch time: a lead not above it cannot work.
  p = ok;
  p.etf_delta_ns = 300 * kUs;
  EXPECT_EQ(SendCycle::Decide(cfg, p), LaunchMode::kSleepNoEtf);
  cfg.launch_time = false;
  EXPECT_EQ(SendCycle::Decide(cfg, ok), LaunchMode::kSleepConfigured);
  SendCycle c;
  c.SetMode(LaunchMode::kTxtime);
  EXPECT_TRUE(c.txtime());
  c.SetMode(LaunchMode::kSleepNoEtf);
  EXPECT_FALSE(c.txtime());
}

}  // namespace
}  // namespace ccomm
