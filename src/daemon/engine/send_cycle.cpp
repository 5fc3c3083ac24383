// SPDX-License-Identifier: Apache-2.0
#include "daemon/engine/send_cycle.h"

namespace ccomm {
namespace {

// A step of CLOCK_TAI against CLOCK_MONOTONIC larger than this re-places the schedule
// (the two are slewed alike: they move apart only at a step; reading both costs some
// hundred ns of noise, which must not shift the grid every tick).
constexpr int64_t kStepNs = 10000;

int64_t FloorDiv(int64_t a, int64_t b) {  // b > 0
  const int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

}  // namespace

const char* LaunchModeName(LaunchMode m) {
  switch (m) {
    case LaunchMode::kOff: return "off";
    case LaunchMode::kTxtime: return "txtime";
    case LaunchMode::kSleepConfigured: return "sleep (launch_time=\"sleep\")";
    case LaunchMode::kSleepPlatform: return "sleep (no SO_TXTIME on this platform)";
    case LaunchMode::kSleepRefused: return "sleep (the socket refused SO_TXTIME)";
    case LaunchMode::kSleepNoEtf: return "sleep (no ETF qdisc for ccommd's frames on the interface)";
  }
  return "?";
}

LaunchMode SendCycle::Decide(const SendCycleConfig& c, const TxtimeProbe& p) {
  if (c.cycle_ns == 0) return LaunchMode::kOff;
  if (!c.launch_time) return LaunchMode::kSleepConfigured;
  if (!p.platform) return LaunchMode::kSleepPlatform;
  if (p.socket_error != 0) return LaunchMode::kSleepRefused;
  // ETF releases a frame `delta` before its launch time: a lead shorter than that (plus
  // the time to build the frames) would hand frames over too late, and ETF drops them.
  if (!p.etf || p.etf_delta_ns >= c.lead_ns) return LaunchMode::kSleepNoEtf;
  return LaunchMode::kTxtime;
}

bool SendCycle::SetClock(bool synced, int64_t tai_minus_mono_ns) {
  tai_minus_mono_.store(tai_minus_mono_ns, std::memory_order_relaxed);
  const CycleClock want = synced ? CycleClock::kTai : CycleClock::kMonotonic;
  const int64_t align = synced ? tai_minus_mono_ns : 0;
  const int64_t had = align_minus_mono_.load(std::memory_order_relaxed);
  const int64_t moved = align > had ? align - had : had - align;
  if (want == clock() && moved <= kStepNs) return false;
  align_minus_mono_.store(align, std::memory_order_relaxed);
  const bool switched = want != clock();
  clock_.store(static_cast<uint32_t>(want), std::memory_order_release);
  generation_.fetch_add(1, std::memory_order_release);
  return switched;
}

uint64_t SendCycle::Place(uint64_t now_mono, uint64_t period_ns) const {
  const int64_t off = align_minus_mono_.load(std::memory_order_relaxed);
  const int64_t period = static_cast<int64_t>(period_ns ? period_ns : cfg_.cycle_ns);
  const int64_t phase = static_cast<int64_t>(cfg_.phase_ns);
  const int64_t earliest = static_cast<int64_t>(now_mono) + off + static_cast<int64_t>(cfg_.lead_ns);
  // Smallest t = k * period + phase >= earliest: k = ceil((earliest - phase) / period).
  const int64_t k = -FloorDiv(phase - earliest, period);
  return static_cast<uint64_t>(k * period + phase - off);
}

}  // namespace ccomm
