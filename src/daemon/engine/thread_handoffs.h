// SPDX-License-Identifier: Apache-2.0
// What ccommd's three threads hand each other while they run, named in one place. After
// Daemon::Start() each part owns its state alone (send_path.h, receive_path.h,
// supervisor.h) and reads the prepared-signals table (prepared_signals.h), which no one
// changes; what crosses a thread is below, each field with its one writer and its readers.
// The other crossings have rules of their own: the segment (store/layout.h: the daemon
// counters, per-signal and per-peer statistics, the doorbell) and the system view
// (system_view_writer.h: one writer per node record).
// A reload (daemon_reload.cpp) needs no field here: the main thread stops the send and
// receive threads (running = false, joined), sets every part up again from the new
// configuration, and starts new ones; pthread_join and pthread_create order all of that
// before and after the loops, so the loops never check for a new configuration.
#pragma once

#include <atomic>
#include <cstdint>

#include "config/config.h"
#include "daemon/engine/send_cycle.h"
#include "store/segment.h"

namespace ccomm {

struct ThreadHandoffs {
  // Main thread (Start, RequestStop, Shutdown) -> the send and receive loops.
  std::atomic<bool> running{false};
  // Send / receive thread -> main thread: one more each turn of the loop; the service
  // watchdog is pinged only while both advance (main.cpp).
  std::atomic<uint64_t> tx_loops{0}, rx_loops{0};
  // Supervision -> receive thread, for stale_by="production" (docs/design.md, "Time"):
  // whether this board's clock is synced, and its CLOCK_REALTIME - CLOCK_MONOTONIC.
  std::atomic<uint32_t> self_clock_synced{0};
  std::atomic<int64_t> self_realtime_offset_ns{0};
  // Receive thread -> supervision: events the receive thread counts and the supervision
  // tick logs, at most every 10 s (no syscall on the receive path). Frames with
  // stale_by="production" values judged by their arrival (clocks not synced); frames of
  // another wire version (docs/protocol.md, "Versioning"), and the last one's
  // version << 16 | sender.
  std::atomic<uint64_t> by_arrival_frames{0};
  // Receive thread -> send thread, multicast fan-out over raw Ethernet: the station
  // address (MAC, 48 bits) that frames of a peer without mac= come from, for the peers
  // whose heartbeats go to them directly (PreparedSignals::learns_station); 0 = none yet.
  std::atomic<uint64_t> peer_station[kMaxNodes] = {};
  std::atomic<uint64_t> other_version_frames{0};
  std::atomic<uint32_t> other_version_last{0};
  // Send on the cycle (send_cycle.h): configured by the send part at start-up; then the
  // supervision tick sets its alignment clock (SetClock) and the send thread reads it
  // (Place, LaunchTai); its own fields say which are atomic. CLOCK_TAI - CLOCK_REALTIME in
  // whole seconds, written once at start-up before the threads run.
  SendCycle send_cycle;
  int64_t tai_minus_realtime_ns = 0;
  /// CLOCK_TAI - CLOCK_MONOTONIC now (send_cycle_daemon.cpp).
  int64_t TaiMinusMonotonicNs() const;

  /// Supervision (and tests): this board's clock for the receive thread.
  void PublishSelfClock(bool synced, int64_t realtime_offset_ns) {
    self_realtime_offset_ns.store(realtime_offset_ns, std::memory_order_relaxed);
    self_clock_synced.store(synced ? 1 : 0, std::memory_order_release);
  }
};

/// One more of daemon counter `c` in the segment (store/layout.h), where the send and
/// receive threads count what they did and refused and clients read it.
inline void Count(const store::Segment& segment, store::DaemonCounter c,
                  std::memory_order order = std::memory_order_relaxed) {
  segment.header()->daemon_counters[c].fetch_add(1, order);
}

}  // namespace ccomm
