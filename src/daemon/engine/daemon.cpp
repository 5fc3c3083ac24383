// SPDX-License-Identifier: Apache-2.0
// Start-up and shutdown of the forwarding engine: what its parts share (segment,
// transport, key, system view, the prepared-signals table), then the parts themselves
// (send_path.h, receive_path.h, supervisor.h).
#include "daemon/engine/daemon.h"
#include "daemon/engine/segment_builder.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "common/platform.h"

namespace ccomm {

Daemon::~Daemon() { Shutdown(); }

int Daemon::Start(const SystemConfig& cfg, uint32_t node_id, const DaemonOptions& opt,
                  std::string* error) {
  cfg_ = &cfg;
  self_ = node_id;
  opt_ = opt;
  supervisor_.Configure(cfg, node_id, opt.ptp_socket, opt.ptp_synced_within_ns);
  const NodeConfig& self = cfg.nodes[node_id];

  // Who do we talk to, and which signals go where.
  const TransportKind kind = opt.force_udp ? TransportKind::kUdp : self.transport;
  table_.Route(cfg, node_id);
  std::vector<PeerAddress> groups;  // multicast fan-out: the groups of the peers we exchange with
  send_.SetWatchdogInterval(opt.watchdog_ns);
  int r = send_.OpenStreams(cfg, node_id, kind, opt.force_udp, &groups, error);
  if (r != 0) return r;

  if (!cfg.network.auth_key_file.empty()) {
    int ar = auth_.Load(cfg.network.auth_key_file, error);
    if (ar != 0) return ar;
  }

  // Shared memory: group "ccomm" if it exists, so members can use it (mode 0660).
  const int gid = platform::NamedGroupId("ccomm");
  gid_ = gid;
  // Two ccommd for one node would both forward and reclaim in one segment: refuse the
  // second (a systemd unit and a hand-started one, say) before it touches anything.
  int holder = 0;
  lock_fd_ = LockNode(store::SegmentName(self.name), gid, &holder);
  if (lock_fd_ == -EBUSY) {
    *error = "a ccommd for node '" + self.name + "' is already running (pid " +
             (holder > 0 ? std::to_string(holder) : std::string("unknown")) + "; it holds " +
             store::SegmentName(self.name) + ".lock, also while stopped): stop it first (systemctl stop ccommd)";
    return -EBUSY;
  }
  if (lock_fd_ < 0) {
    const int e = lock_fd_;
    *error = "cannot lock " + store::SegmentName(self.name) + ".lock: " + strerror(-e);
    return e;
  }
  const std::string fit = SegmentFitProblem(cfg, node_id, store::SegmentName(self.name));
  if (!fit.empty()) {
    *error = fit;
    return -ENOSPC;
  }
  r = CreateOrAdoptSegment(&segment_, cfg, node_id, store::SegmentName(self.name), gid, &adopted_, error);
  if (r != 0) return r;
  table_.Resolve(segment_, auth_.enabled());
  supervisor_.Prepare(adopted_);
  send_.Prepare(adopted_);
  receive_.Prepare(cfg, node_id, kind, opt.recv_timeout_ms);

  if (!table_.exchanges_any()) {
    // Local-only node: apps talk through shared memory; no socket, no privileges needed.
    transport_ = Transport();
  } else {
    const TransportProvider* provider = FindTransport(kind);
    if (!provider) {  // not in this build (raw Ethernet on Windows)
      *error = RawEthernetUnavailable(self);
      return -ENOTSUP;
    }
    r = provider->open(cfg.network, self, opt.recv_timeout_ms, &transport_, error);
    if (r != 0) return r;
    if (table_.multicast()) {
      r = transport_.JoinGroups(groups.data(), groups.size(), error);
      if (r != 0) return r;
    }
    // Before the capabilities go: the watch needs CAP_NET_RAW (a UDP node may lack it).
    supervisor_.WatchForeignFrames(cfg, node_id, kind);
  }
  r = view_.Start(cfg, node_id, kind, opt.force_udp, &segment_, &transport_, &auth_, gid, error);
  if (r != 0) return r;
  send_.StartCycle();  // send on the cycle (send_cycle_daemon.cpp)

  StartRunning();
  return 0;
}

// The periods start now; clients see this ccommd alive; the I/O threads may run.
void Daemon::StartRunning() {
  const uint64_t now = platform::MonotonicNs();
  send_.StartPeriods(now);
  store::SegmentHeader* h = segment_.header();
  h->daemon_pid.store(static_cast<int32_t>(platform::ProcessId()), std::memory_order_release);
  h->daemon_heartbeat_ns.store(now, std::memory_order_release);
  handoffs_.running.store(true);
}

void Daemon::EnterIoThread(const char* name) {
  const RealtimeConfig& rt = cfg_->nodes[self_].realtime;
  char thread_name[16];
  snprintf(thread_name, sizeof thread_name, "ccommd-%s", name);  // ccommd-send, ccommd-receive
  platform::NameThisThread(thread_name);
  if (!opt_.no_realtime) {
    platform::RealtimeRequest want;
    want.cpu = rt.cpu;
    want.fifo_priority = rt.priority;
    const platform::RealtimeResult got = platform::SetUpRealtime(want);
    if (got.fifo_priority != 0)
      Log(LogLevel::kWarning, "%s thread: SCHED_FIFO %d refused (needs CAP_SYS_NICE or RLIMIT_RTPRIO); running "
          "SCHED_OTHER", name, rt.priority);
    if (got.cpu != 0) Log(LogLevel::kWarning, "%s thread: cannot pin to CPU %d", name, rt.cpu);
  }
  platform::PrefaultStack(32 * 1024);
}

void Daemon::RunTx() {
  EnterIoThread("send");
  send_.RunTx();
}

void Daemon::RunRx() {
  EnterIoThread("receive");
  receive_.RunRx();
}

void Daemon::RequestStop() {
  handoffs_.running.store(false);
  if (segment_.is_open()) {
    segment_.header()->tx_doorbell.fetch_add(1);
    platform::FutexWake(&segment_.header()->tx_doorbell, 1);
  }
}

void Daemon::Shutdown() {
  handoffs_.running.store(false);
  transport_.Close();
  supervisor_.Stop();
  view_.Stop();
  if (segment_.is_open()) {
    segment_.header()->daemon_pid.store(0, std::memory_order_release);
    segment_.Close();  // the segment stays: clients keep reading (stale) values
  }
  platform::UnlockExclusive(lock_fd_);  // the next ccommd of this node may start
  lock_fd_ = -1;
}

}  // namespace ccomm
