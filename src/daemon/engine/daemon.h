// SPDX-License-Identifier: Apache-2.0
// ccommd's forwarding engine, split by thread: a send part (send_path.h, the send thread,
// woken by the shared-memory doorbell or its periodic/heartbeat deadline), a receive part
// (receive_path.h, the receive thread, blocked in the socket) and supervision
// (supervisor.h, a tick on the main thread), each owning its state, over one
// prepared-signals table built in Start() and constant while the I/O threads run (a reload
// builds it again with them stopped: daemon_reload.cpp; prepared_signals.h);
// what the threads hand each other is in thread_handoffs.h. Daemon owns what they share
// (the segment, the transport, the frame key, the system view) and starts them.
// Everything is allocated in Start(); the three loops never allocate (test_alloc.py).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "config/config.h"
#include "daemon/engine/prepared_signals.h"
#include "daemon/engine/receive_path.h"
#include "daemon/engine/send_path.h"
#include "daemon/engine/supervisor.h"
#include "daemon/engine/system_view_writer.h"
#include "daemon/engine/thread_handoffs.h"
#include "daemon/net/transport.h"
#include "daemon/security/auth.h"
#include "store/segment.h"

namespace ccomm {

struct DaemonOptions {
  std::string config_path = "/etc/ccomm/signals.xml";
  std::string node;            // empty = identify (node_identity.h)
  bool force_udp = false;      // --transport udp: ignore transport="raw" in the file
  bool check_only = false;
  bool which_node = false;     // --which-node: print the node this board is and exit
  bool no_realtime = false;    // --no-rt: skip mlockall / SCHED_FIFO (tests, unprivileged)
  int verbosity = 6;           // LogLevel
  int recv_timeout_ms = 50;  // main.cpp: the platform's IdleRecvTimeoutMs (io_threads.h)
  std::string ptp_socket = "/var/run/ptp4l";  // --ptp-socket; empty: not asked (ptp_state.h)
  bool ptp_socket_given = false;               // --ptp-socket given: <clock socket=> does not apply
  bool clock_config = false;                   // --clock-config: print ptp4l.conf for the node, exit
  int64_t ptp_synced_within_ns = 1000000;      // |offset from master| of a synced slave
  uint64_t watchdog_ns = 0;  // the service manager's watchdog interval (sd_notify.h), 0: none
};

class Daemon {
 public:
  Daemon()
      : context_{segment_, transport_, auth_, view_, handoffs_, table_},
        send_(context_),
        receive_(context_),
        supervisor_(context_) {}
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;
  ~Daemon();

  /// Creates/adopts the segment, opens the transport, preallocates everything.
  int Start(const SystemConfig& cfg, uint32_t node_id, const DaemonOptions& opt, std::string* error);
  void RunTx();   // send thread body, returns after RequestStop()
  void RunRx();   // receive thread body
  /// Supervision: daemon heartbeat, peer liveness, staleness counters. Call again at
  /// NextSupervisionNs() (Supervisor::NextTickNs: when something falls due, at most 100 ms).
  void Supervise(uint64_t now_ns) { supervisor_.Tick(now_ns); }
  uint64_t NextSupervisionNs() const { return supervisor_.NextTickNs(); }
  /// What supervision hands the receive thread for stale_by="production" (tests call it too).
  void PublishSelfClock(bool synced, int64_t realtime_offset_ns) {
    handoffs_.PublishSelfClock(synced, realtime_offset_ns);
  }
  void RequestStop();

  // Reload (daemon_reload.cpp; docs/usage.md, "Reload"), on the main thread in two steps.
  /// Step 1, with the I/O threads running: "" if `next` can replace the running
  /// configuration in this process, else why not, as "FILE:LINE: error: ..." lines: what
  /// the open socket, the send cycle and the key were set up from at start stays (a
  /// restart applies those).
  std::string ReloadRefusal(const SystemConfig& next, uint32_t node_id) const;
  /// Step 2, with the I/O threads stopped (RequestStop, both joined): every part set up
  /// again from `next` over the open transport, as Start would, and running again for new
  /// I/O threads. The segment is re-adopted when a restart would re-adopt it (same
  /// layout: values and queued events stay, sequence numbers go on), else replaced (the
  /// old one retired, as at a restart). 0, or -errno with `error`: then nothing runs
  /// until a Reconfigure with the old configuration succeeds. `next` must outlive its use.
  int Reconfigure(const SystemConfig& next, uint32_t node_id, std::string* error);

  /// Detaches from the segment (which stays for the clients: their values go stale).
  void Shutdown();

  /// Loop iteration counters, for the watchdog: both must advance between pings.
  uint64_t tx_loops() const { return handoffs_.tx_loops.load(std::memory_order_relaxed); }
  uint64_t rx_loops() const { return handoffs_.rx_loops.load(std::memory_order_relaxed); }
  const store::Segment& segment() const { return segment_; }
  const char* transport_name() const { return transport_.ops ? transport_.ops->name : "none"; }
  bool adopted_segment() const { return adopted_; }

 private:
  /// Real-time set-up of an I/O thread: SCHED_FIFO and CPU from <realtime>, stack prefault.
  void EnterIoThread(const char* name);
  void StartRunning();

  const SystemConfig* cfg_ = nullptr;
  uint32_t self_ = 0;
  DaemonOptions opt_;
  // What the parts share (EngineContext), set up in Start().
  store::Segment segment_;
  int lock_fd_ = -1;  // the node's lock (LockNode), held while this ccommd lives
  int gid_ = -1;      // group "ccomm" of the segment and the view, or -1
  bool adopted_ = false;
  Transport transport_;
  auth::FrameAuth auth_;                   // per-frame MAC (off unless auth_key_file is set)
  SystemViewWriter view_;                  // the system view: node summaries out and in (system_view_writer.h)
  ThreadHandoffs handoffs_;
  PreparedSignals table_;
  const EngineContext context_;  // the above, as the parts see them
  // The parts, one per thread.
  SendPath send_;
  ReceivePath receive_;
  Supervisor supervisor_;
};

}  // namespace ccomm
