// SPDX-License-Identifier: Apache-2.0
// ccommd's supervision part (supervisor.cpp), run by the main thread on its own schedule
// (NextTickNs: when something falls due, at least every 100 ms; every 10 ms while the
// send cycle runs): the daemon heartbeat in the segment, peer liveness against peer_timeout_ms, stale
// transitions of consumed signals, the reclaim of slots left by dead writers, the
// kernel's drop count, frames of other transports (foreign_frames.h), this board's
// clock (ptp_state.h) and the log lines of what the receive thread counted (at most
// every 10 s: no syscall on the receive path), and this node's summary (the system
// view, sent from here). After Daemon::Start() only the main thread touches this object.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "config/config.h"
#include "daemon/clock/ptp_state.h"
#include "daemon/engine/engine_context.h"
#include "daemon/engine/prepared_signals.h"
#include "daemon/engine/system_view_writer.h"
#include "daemon/engine/thread_handoffs.h"
#include "daemon/net/foreign_frames.h"
#include "daemon/net/transport.h"
#include "store/reclaim.h"
#include "store/segment.h"

namespace ccomm {

class Supervisor {
 public:
  explicit Supervisor(const EngineContext& ctx) : ctx_(ctx) {}
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Start-up, from the configuration: this board's clock is asked at `ptp_socket`
  /// (empty: not asked) and synced within `ptp_synced_within_ns`.
  void Configure(const SystemConfig& cfg, uint32_t self, const std::string& ptp_socket,
                 int64_t ptp_synced_within_ns);
  /// Start-up, once the segment exists: no peer alive yet; in a re-adopted segment, the
  /// slots of writers that died while no ccommd ran are freed now. `reload`: set up
  /// again by a reload (Daemon::Reconfigure), peers keep their liveness.
  void Prepare(bool adopted, bool reload = false);
  /// Start-up, while ccommd still has its capabilities: the watch for frames of other
  /// transports or EtherTypes (CAP_NET_RAW); without it that is logged and left off.
  void WatchForeignFrames(const SystemConfig& cfg, uint32_t self, TransportKind kind);
  /// One supervision tick.
  void Tick(uint64_t now);
  /// When the next tick is due, as the last Tick() planned it. Every kTickNs (as a fixed
  /// tick would) while the send cycle runs or ptp4l's answers are due; otherwise at the
  /// earliest instant something falls due (a peer's timeout, a consumed signal going
  /// stale, a summary, a poll, a log line held back), at most kIdleTickNs ahead (the
  /// daemon heartbeat: ccomm_daemon_alive allows 1 s), never sooner than kTickNs. Writes
  /// of this node's signals change nothing (the summary reads a produced signal's age
  /// off its newest value): idle or producing at 1 kHz, about 10 wake-ups a second.
  uint64_t NextTickNs() const { return next_tick_ns_; }
  static constexpr uint64_t kTickNs = 10'000'000;
  static constexpr uint64_t kIdleTickNs = 100'000'000;
  void Stop() { foreign_.Close(); }

 private:
  void SuperviseClock(uint64_t now);  // this board's clock into the segment and the log
  void LogClockChange();  // the clock state it changed to, one line
  void SuperviseSendCycle(uint64_t now, bool synced);  // send_cycle_daemon.cpp

  const EngineContext ctx_;  // what the parts share (Daemon owns it)
  const SystemConfig* cfg_ = nullptr;
  uint32_t self_ = 0;
  uint64_t peer_timeout_ns_ = 0;

  ptp::Monitor ptp_;                       // this board's clock state
  ForeignFrameWatch foreign_;              // mismatched boards' frames
  std::vector<uint32_t> consumed_;         // ids of signals consumed here
  std::vector<uint8_t> fresh_;             // signal -> was fresh at last tick
  std::vector<store::SlotSuspect> reclaim_suspects_;  // slot -> what the last scan saw
  uint64_t next_tick_ns_ = 0;
  uint64_t next_reclaim_ns_ = 0;
  uint64_t next_drops_ns_ = 0;
  uint32_t socket_drops_seen_ = 0;         // the kernel's count for our socket at the last look
  uint64_t by_arrival_logged_ = 0, by_arrival_next_log_ns_ = 0;
  uint64_t other_version_logged_ = 0, other_version_next_log_ns_ = 0;
  uint64_t etf_drops_logged_ = 0, etf_drops_next_log_ns_ = 0;  // send on the cycle
};

}  // namespace ccomm
