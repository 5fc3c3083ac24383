// SPDX-License-Identifier: Apache-2.0
// Start-up, supervision and shutdown of the forwarding engine (send/receive paths are
// in tx_path.cpp and rx_path.cpp).
#include "daemon/daemon.h"
#include "daemon/segment_builder.h"
#include "daemon/sd_notify.h"

#include <errno.h>
#include <string.h>
#include <unistd.h>

#include "common/platform.h"
#include "store/freshness.h"
#include "store/reclaim.h"

namespace ccomm {

Daemon::~Daemon() { Shutdown(); }

int Daemon::Start(const SystemConfig& cfg, uint32_t node_id, const DaemonOptions& opt,
                  std::string* error) {
  cfg_ = &cfg;
  self_ = node_id;
  opt_ = opt;
  ptp_.Configure(opt.ptp_socket, opt.ptp_synced_within_ns, static_cast<uint8_t>(cfg.clock.domain));
  const NodeConfig& self = cfg.nodes[node_id];
  const size_t n = cfg.signals.size(), m = cfg.nodes.size();
  heartbeat_ns_ = uint64_t{cfg.network.heartbeat_ms} * 1000000;
  // main() pings the systemd watchdog only while the send loop advances: an idle loop
  // must turn at least four times per watchdog interval.
  const uint64_t watchdog_ns = sd::WatchdogIntervalNs();
  idle_sleep_ns_ = watchdog_ns && watchdog_ns / 4 < heartbeat_ns_ ? watchdog_ns / 4 : heartbeat_ns_;
  peer_timeout_ns_ = uint64_t{cfg.network.peer_timeout_ms} * 1000000;

  // Who do we talk to, and which signals go where.
  peers_tx_ = std::vector<PeerTx>(m + 1);  // + the group stream
  group_tx_ = static_cast<uint32_t>(m);
  fanout_multicast_ = cfg.network.fanout == Fanout::kMulticast;
  peers_rx_.assign(m, PeerRx());
  consumers_.assign(n, {});
  due_ns_.assign(n, 0);
  fwd_cursors_.assign(n, store::RingCursor());
  collected_states_.assign(n, 0);  // RunTx never allocates: a state is taken at most once a round
  fresh_.assign(n, 0);
  TransportKind kind = opt.force_udp ? TransportKind::kUdp : self.transport;
  for (size_t i = 0; i < n; ++i) {
    const SignalConfig& s = cfg.signals[i];
    bool here = s.producer == node_id;
    bool consumed_here = false;
    for (uint32_t c : s.consumers) {
      if (here && c != node_id) {
        peers_tx_[c].active = true;
        // Multicast fan-out: once, to our group, whatever the number of consumers.
        if (!fanout_multicast_) consumers_[i].push_back(c);
        else if (consumers_[i].empty()) consumers_[i].push_back(group_tx_);
      }
      if (c == node_id) consumed_here = true;
    }
    if (!here && consumed_here) {
      peers_tx_[s.producer].active = true;  // heartbeats let the producer supervise us too
      consumed_.push_back(static_cast<uint32_t>(i));
    }
    if (here && !consumers_[i].empty() && s.period_us) periodic_.push_back(static_cast<uint32_t>(i));
  }
  std::vector<PeerAddress> groups;  // multicast fan-out: the groups of the peers we exchange with
  for (uint32_t p = 0; p < m; ++p) {
    PeerTx& pt = peers_tx_[p];
    if (!pt.active) continue;
    TransportKind pk = opt.force_udp ? TransportKind::kUdp : cfg.nodes[p].transport;
    if (pk != kind) {
      *error = "node '" + self.name + "' uses " + (kind == TransportKind::kRaw ? "raw" : "udp") +
               " but its peer '" + cfg.nodes[p].name + "' uses " +
               (pk == TransportKind::kRaw ? "raw" : "udp") + ": nodes that exchange signals need the same transport";
      return -EINVAL;
    }
    if (!PeerAddressFor(cfg.network, cfg.nodes[p], kind, &pt.addr)) {
      *error = "peer '" + cfg.nodes[p].name + "' has no usable ip/multicast for UDP";
      return -EINVAL;
    }
    pt.writer = wire::FrameWriter(pt.buf, sizeof pt.buf);
    pt.dest = static_cast<uint16_t>(p);
    pt.sends = !fanout_multicast_;
    if (pt.sends) senders_.push_back(p);
    if (fanout_multicast_) groups.push_back(GroupAddressFor(cfg.network, p, kind));
    // UDP frames must come from the peer's own address (rule 2); raw frames carry no
    // address worth checking (any station can send any source MAC).
    if (kind == TransportKind::kUdp && !cfg.nodes[p].ip.empty())
      platform::ParseIpv4(cfg.nodes[p].ip.c_str(), &peers_rx_[p].ipv4);
  }

  if (fanout_multicast_ && !groups.empty()) {
    // Every node's summary goes to the summary group, which every node with a socket
    // joins: any board sees the whole system (ccomm stats --all), not only its peers.
    if (cfg.network.summary_ms != 0) groups.push_back(GroupAddressFor(cfg.network, kSummaryGroup, kind));
    PeerTx& g = peers_tx_[group_tx_];
    g.active = g.sends = true;
    g.dest = wire::kDestAll;
    g.addr = GroupAddressFor(cfg.network, node_id, kind);
    g.writer = wire::FrameWriter(g.buf, sizeof g.buf);
    senders_.push_back(group_tx_);
  }
  senders_.shrink_to_fit();

  replay_.assign(m, auth::ReplayWindow());
  if (!cfg.network.auth_key_file.empty()) {
    int ar = auth_.Load(cfg.network.auth_key_file, error);
    if (ar != 0) return ar;
  }

  // Shared memory: group "ccomm" if it exists, so members can use it (mode 0660).
  const int gid = platform::NamedGroupId("ccomm");
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
  int r = CreateOrAdoptSegment(&segment_, cfg, node_id, store::SegmentName(self.name), gid, &adopted_, error);
  if (r != 0) return r;
  reclaim_suspects_.assign(store::SlotCount(segment_), store::SlotSuspect());
  InitLargeValues();
  history_.assign(n, store::RingView());
  for (uint32_t i = 0; i < n; ++i) history_[i] = segment_.history(i);
  for (uint32_t p = 0; p < m; ++p) segment_.peer(p).alive.store(0);  // a re-adopted segment's are stale
  if (adopted_) {
    // Writers that died while this ccommd was down may have left slots half-written.
    size_t freed = store::ReclaimAbandonedSlots(segment_, &reclaim_suspects_);
    if (freed) Log(LogLevel::kNotice, "reclaimed %zu slots left by dead writers", freed);
  }
  for (size_t i = 0; i < n; ++i) {
    const auto& d = segment_.dir(static_cast<uint32_t>(i));
    if ((d.flags & store::kSigEvent) && (d.flags & store::kSigForwarded)) {
      // Resume where the previous ccommd stopped: queued events are still sent.
      fwd_cursors_[i].next = store::RingForwardCursor(segment_.ring(static_cast<uint32_t>(i)));
    }
  }
  PrepareRxTx();

  bool any_peer = false;
  for (const PeerTx& pt : peers_tx_) any_peer = any_peer || pt.active;
  if (!any_peer) {
    // Local-only node: apps talk through shared memory; no socket, no privileges needed.
    transport_ = Transport();
  } else {
    r = kind == TransportKind::kRaw ? OpenRawTransport(cfg.network, self, opt.recv_timeout_ms, &transport_, error)
                                    : OpenUdpTransport(cfg.network, self, opt.recv_timeout_ms, &transport_, error);
    if (r != 0) return r;
    if (fanout_multicast_) {
      r = transport_.JoinGroups(groups.data(), groups.size(), error);
      if (r != 0) return r;
    }
    // Before the capabilities go: the watch needs CAP_NET_RAW (a UDP node may lack it).
    const int fr = foreign_.Open(cfg.network, self, kind);
    if (fr != 0)
      Log(LogLevel::kInfo, "not watching for frames of other transports/EtherTypes (%s): a mismatched board "
          "shows only as a peer that never comes up", strerror(-fr));
  }
  r = view_.Start(cfg, node_id, kind, opt.force_udp, &segment_, &transport_, &auth_, gid, error);
  if (r != 0) return r;
  StartSendCycle();  // send on the cycle (send_cycle_daemon.cpp)

  uint64_t now = platform::MonotonicNs();
  for (uint32_t id : periodic_) due_ns_[id] = now;
  store::SegmentHeader* h = segment_.header();
  h->daemon_pid.store(static_cast<int32_t>(platform::ProcessId()), std::memory_order_release);
  h->daemon_heartbeat_ns.store(now, std::memory_order_release);
  running_.store(true);
  return 0;
}

void Daemon::Supervise(uint64_t now) {
  store::SegmentHeader* h = segment_.header();
  h->daemon_heartbeat_ns.store(now, std::memory_order_release);
  if (now >= next_reclaim_ns_) {
    next_reclaim_ns_ = now + 1000000000ull;
    size_t freed = store::ReclaimAbandonedSlots(segment_, &reclaim_suspects_);
    if (freed) h->daemon_counters[store::kSlotsReclaimed].fetch_add(freed, std::memory_order_relaxed);
  }
  if (now >= next_drops_ns_ && transport_.ops) {
    // Frames lost before ccommd saw them (its receive thread starved, buffer full):
    // otherwise only a sequence gap would tell, without the reason.
    next_drops_ns_ = now + 100000000ull;
    uint32_t drops = 0;
    if (transport_.SocketDrops(&drops) == 0) {
      h->daemon_counters[store::kSocketDrops].fetch_add(drops - socket_drops_seen_, std::memory_order_relaxed);
      socket_drops_seen_ = drops;
    }
  }
  const uint64_t other_version = other_version_frames_.load(std::memory_order_relaxed);
  if (other_version != other_version_logged_ && now >= other_version_next_log_ns_) {
    const uint32_t last = other_version_last_.load(std::memory_order_relaxed);
    Log(LogLevel::kError,
        "refused %llu frame(s) of wire version %u (the last from node id %u): this ccommd speaks version %u; "
        "a board runs another ccomm version (counted in frames_bad, docs/protocol.md \"Versioning\")",
        static_cast<unsigned long long>(other_version - other_version_logged_), last >> 16, last & 0xFFFF,
        unsigned{wire::kVersion});
    other_version_logged_ = other_version;
    other_version_next_log_ns_ = now + 10000000000ull;
  }
  if (const uint32_t foreign = foreign_.Poll(now))
    h->daemon_counters[store::kFramesForeign].fetch_add(foreign, std::memory_order_relaxed);
  for (uint32_t p = 0; p < peers_rx_.size(); ++p) {
    if (!peers_tx_[p].active) continue;
    store::PeerStats& ps = segment_.peer(p);
    // alive before last: the receive thread stores last, then sets alive (release), so a
    // peer seen alive here comes with its newest last. `now` was read before `last`: a
    // frame that arrived since (last > now) is no silence.
    bool alive = ps.alive.load(std::memory_order_acquire) != 0;
    uint64_t last = ps.last_rx_ns.load(std::memory_order_acquire);
    if (alive && now > last && now - last > peer_timeout_ns_) {
      ps.alive.store(0, std::memory_order_release);
      ps.down_transitions.fetch_add(1, std::memory_order_relaxed);
      Log(LogLevel::kWarning, "peer '%s' lost: nothing received for %u ms", cfg_->nodes[p].name.c_str(),
          cfg_->network.peer_timeout_ms);
    }
  }
  SuperviseClock(now);
  view_.Tick(now);  // this node's summary, rate-limited (system_view_writer.h)
  for (uint32_t id : consumed_) {
    const SignalConfig& s = cfg_->signals[id];
    if (!s.stale_after_ms) continue;
    uint64_t last = segment_.stats(id).last_rx_ns.load(std::memory_order_relaxed);
    bool fresh = !store::IsStale(last != 0, last < now ? now - last : 0, uint64_t{s.stale_after_ms} * 1000000);
    if (fresh_[id] && !fresh) segment_.stats(id).stale_transitions.fetch_add(1, std::memory_order_relaxed);
    fresh_[id] = fresh;
  }
}

void Daemon::EnterIoThread(const char* name) {
  const RealtimeConfig& rt = cfg_->nodes[self_].realtime;
  if (!opt_.no_realtime) {
    if (rt.priority > 0 && platform::SetFifoPriority(rt.priority) != 0)
      Log(LogLevel::kWarning, "%s thread: SCHED_FIFO %d refused (needs CAP_SYS_NICE or RLIMIT_RTPRIO); running "
          "SCHED_OTHER", name, rt.priority);
    if (rt.cpu >= 0 && platform::PinToCpu(rt.cpu) != 0)
      Log(LogLevel::kWarning, "%s thread: cannot pin to CPU %d", name, rt.cpu);
  }
  platform::PrefaultStack(32 * 1024);
}

void Daemon::RequestStop() {
  running_.store(false);
  if (segment_.is_open()) {
    segment_.header()->tx_doorbell.fetch_add(1);
    platform::FutexWake(&segment_.header()->tx_doorbell, 1);
  }
}

void Daemon::Shutdown() {
  running_.store(false);
  transport_.Close();
  foreign_.Close();
  view_.Stop();
  if (segment_.is_open()) {
    segment_.header()->daemon_pid.store(0, std::memory_order_release);
    segment_.Close();  // the segment stays: clients keep reading (stale) values
  }
  platform::UnlockExclusive(lock_fd_);  // the next ccommd of this node may start
  lock_fd_ = -1;
}

}  // namespace ccomm
