// SPDX-License-Identifier: Apache-2.0
// Supervision: this board's clock state (ptp_state.h) into its segment, where
// ccomm_get_clock_state() and `ccomm stats` read it, and into the log when it changes.
#include "daemon/daemon.h"

#include "common/platform.h"

namespace ccomm {

void Daemon::SuperviseClock(uint64_t now) {
  const bool changed = ptp_.Tick(now);
  store::PeerStats& self = segment_.peer(self_);
  const uint64_t word = static_cast<uint64_t>(ptp_.state()) | uint64_t{ptp_.port_state()} << 8 | uint64_t{1} << 16;
  self.clock_offset_ns.store(static_cast<uint64_t>(ptp_.offset_ns()), std::memory_order_relaxed);
  self.clock_path_delay_ns.store(static_cast<uint64_t>(ptp_.path_delay_ns()), std::memory_order_relaxed);
  self.clock_state.store(word, std::memory_order_release);
  PublishSelfClock(ptp_.state() == ptp::ClockState::kSynced, platform::RealtimeOffsetNs());
  SuperviseSendCycle(now, ptp_.state() == ptp::ClockState::kSynced);  // send on the cycle
  const uint64_t by_arrival = by_arrival_frames_.load(std::memory_order_relaxed);
  if (by_arrival != by_arrival_logged_ && now >= by_arrival_next_log_ns_) {
    Log(LogLevel::kNotice, "%llu frame(s) with stale_by=\"production\" values judged by their arrival: this "
        "board's clock (%s) or the sender's is not synced, or no current summary of the sender",
        static_cast<unsigned long long>(by_arrival - by_arrival_logged_), ptp::ClockStateName(ptp_.state()));
    by_arrival_logged_ = by_arrival;
    by_arrival_next_log_ns_ = now + 10000000000ull;
  }
  if (!changed) return;
  const char* name = ptp::ClockStateName(ptp_.state());
  switch (ptp_.state()) {
    case ptp::ClockState::kSynced:
      Log(LogLevel::kNotice, "clock synced (ptp4l at %s: port state %u, offset %lld ns)", ptp_.path().c_str(),
          unsigned{ptp_.port_state()}, static_cast<long long>(ptp_.offset_ns()));
      break;
    case ptp::ClockState::kLost:
      Log(LogLevel::kWarning, "clock %s: ptp4l at %s stopped answering or its port failed (port state %u); "
          "ages are local again", name, ptp_.path().c_str(), unsigned{ptp_.port_state()});
      break;
    default:
      Log(LogLevel::kNotice, "clock %s (ptp4l at %s, port state %u)", name, ptp_.path().c_str(),
          unsigned{ptp_.port_state()});
  }
}

}  // namespace ccomm
