// SPDX-License-Identifier: Apache-2.0
// Send on the cycle (<realtime send_cycle_us=...>, docs/config.md; docs/design.md, "Time"):
// a node's periodic frames leave at instants  k * period + phase  of a clock every board
// shares. This type owns that schedule and the launch times handed to the kernel; it
// touches no socket, so tests drive it with made-up clocks (send_cycle_test.cpp).
//
// Clocks. The send thread keeps CLOCK_MONOTONIC; instants are aligned on CLOCK_TAI while
// this board's clock is synced (ptp_state.h, the supervision tick calls SetClock), else on
// CLOCK_MONOTONIC itself (said in the log). Launch times for SO_TXTIME are always in
// CLOCK_TAI (the ETF qdisc accepts no other clock in software mode). The cycle divides one
// second, so boards whose TAI offsets differ by whole seconds (one has a UTC-TAI offset
// set, another not) still share the grid.
//
// Launch. With launch times (kTxtime) the send thread wakes `lead` before the instant,
// builds the frames and hands them to the kernel with the instant as launch time: the
// ETF qdisc holds them until then. Otherwise (kSleep) it builds them at the same wake-up,
// sleeps until the instant and sends. Decide() says which, and why (one reason, logged
// once and shown by `ccomm stats`).
#pragma once

#include <atomic>
#include <cstdint>

#include "daemon/net/txtime_probe.h"

namespace ccomm {

enum class CycleClock : uint32_t { kMonotonic = 0, kTai = 1 };

// Why frames are (not) sent with launch times: the first of these that applies.
enum class LaunchMode : uint32_t {
  kOff = 0,          // no send cycle configured
  kTxtime = 1,       // SO_TXTIME launch times, an ETF qdisc holds the frames
  kSleepConfigured,  // launch_time="sleep" in the file
  kSleepPlatform,    // no SO_TXTIME on this platform (Windows)
  kSleepRefused,     // the kernel refused SO_TXTIME on the socket (EPERM: no CAP_NET_ADMIN at start)
  kSleepNoEtf,       // no ETF qdisc on the interface for ccommd's frames (priority kTxtimePriority)
};
// Counted in the segment (store/layout.h, `ccomm stats`): cycle_rounds, cycle_late,
// cycle_etf_drops (frames the ETF qdisc dropped, SO_EE_CODE_TXTIME_*: logged, not a switch
// back to sleeping, which frames already queued would not survive), cycle_launch (the mode).
const char* LaunchModeName(LaunchMode m);

struct SendCycleConfig {
  uint64_t cycle_ns = 0;  // 0: no send cycle (frames leave when due, as without the option)
  uint64_t phase_ns = 0;  // < cycle_ns
  uint64_t lead_ns = 0;   // < cycle_ns: how early the send thread wakes
  bool launch_time = true;  // launch_time="auto" (false: "sleep")
};

class SendCycle {
 public:
  void Configure(const SendCycleConfig& c) { cfg_ = c; }
  bool enabled() const { return cfg_.cycle_ns != 0; }
  const SendCycleConfig& config() const { return cfg_; }

  // The launch decision from the configuration and the probe (pure).
  static LaunchMode Decide(const SendCycleConfig& c, const TxtimeProbe& p);
  void SetMode(LaunchMode m) { mode_.store(static_cast<uint32_t>(m), std::memory_order_relaxed); }
  LaunchMode mode() const { return static_cast<LaunchMode>(mode_.load(std::memory_order_relaxed)); }
  bool txtime() const { return mode() == LaunchMode::kTxtime; }

  // Supervision tick: this board's clock (synced per the ptp monitor) and CLOCK_TAI minus
  // CLOCK_MONOTONIC now. A change of alignment clock bumps generation(): the send thread
  // then places its signals on the new grid (Place). Returns true when the alignment changed.
  bool SetClock(bool synced, int64_t tai_minus_mono_ns);
  CycleClock clock() const { return static_cast<CycleClock>(clock_.load(std::memory_order_acquire)); }
  uint32_t generation() const { return generation_.load(std::memory_order_acquire); }

  // Send thread. The first instant of a signal of period `period_ns` (a multiple of the
  // cycle) that the thread can still reach: the smallest t = k * period + phase (aligned
  // clock) with t - lead >= now. Returned in CLOCK_MONOTONIC ns.
  uint64_t Place(uint64_t now_mono, uint64_t period_ns) const;
  // When to wake for an instant.
  uint64_t WakeAt(uint64_t instant_mono) const { return instant_mono - cfg_.lead_ns; }
  // The instant's launch time on CLOCK_TAI (SCM_TXTIME).
  uint64_t LaunchTai(uint64_t instant_mono) const {
    return static_cast<uint64_t>(static_cast<int64_t>(instant_mono) + tai_minus_mono_.load(std::memory_order_relaxed));
  }

 private:
  SendCycleConfig cfg_;
  std::atomic<uint32_t> mode_{static_cast<uint32_t>(LaunchMode::kOff)};
  std::atomic<uint32_t> clock_{static_cast<uint32_t>(CycleClock::kMonotonic)};
  std::atomic<uint32_t> generation_{0};
  std::atomic<int64_t> align_minus_mono_{0};  // 0 on CLOCK_MONOTONIC, else tai - mono
  std::atomic<int64_t> tai_minus_mono_{0};
};

}  // namespace ccomm
