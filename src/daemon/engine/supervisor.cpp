// SPDX-License-Identifier: Apache-2.0
// The supervision part (supervisor.h): the main thread's tick.
#include "daemon/engine/supervisor.h"

#include <string.h>

#include "common/platform.h"
#include "store/freshness.h"
#include "wire/wire.h"

namespace ccomm {

void Supervisor::Configure(const SystemConfig& cfg, uint32_t self, const std::string& ptp_socket,
                           int64_t ptp_synced_within_ns) {
  cfg_ = &cfg;
  self_ = self;
  ptp_.Configure(ptp_socket, ptp_synced_within_ns, static_cast<uint8_t>(cfg.clock.domain));
  peer_timeout_ns_ = uint64_t{cfg.network.peer_timeout_ms} * 1000000;
  fresh_.assign(cfg.signals.size(), 0);
  consumed_.clear();
  for (size_t i = 0; i < cfg.signals.size(); ++i) {
    const SignalConfig& s = cfg.signals[i];
    if (s.producer == self) continue;
    for (uint32_t c : s.consumers)
      if (c == self) {
        consumed_.push_back(static_cast<uint32_t>(i));
        break;
      }
  }
}

void Supervisor::Prepare(bool adopted, bool reload) {
  reclaim_suspects_.assign(store::SlotCount(ctx_.segment), store::SlotSuspect());
  // A re-adopted segment's peers were alive for the previous ccommd; after a reload
  // that kept the segment they are for this one, and stay as they are.
  if (!(adopted && reload))
    for (uint32_t p = 0; p < ctx_.table.node_count(); ++p) ctx_.segment.peer(p).alive.store(0);
  if (adopted) {
    // Writers that died while this ccommd was down may have left slots half-written.
    size_t freed = store::ReclaimAbandonedSlots(ctx_.segment, &reclaim_suspects_);
    if (freed) Log(LogLevel::kNotice, "reclaimed %zu slots left by dead writers", freed);
  }
}

void Supervisor::WatchForeignFrames(const SystemConfig& cfg, uint32_t self, TransportKind kind) {
  const int fr = foreign_.Open(cfg.network, cfg.nodes[self], kind);
  if (fr != 0)
    Log(LogLevel::kInfo, "not watching for frames of other transports/EtherTypes (%s): a mismatched board "
        "shows only as a peer that never comes up", strerror(-fr));
}

void Supervisor::Tick(uint64_t now) {
  store::SegmentHeader* h = ctx_.segment.header();
  h->daemon_heartbeat_ns.store(now, std::memory_order_release);
  if (now >= next_reclaim_ns_) {
    next_reclaim_ns_ = now + 1000000000ull;
    size_t freed = store::ReclaimAbandonedSlots(ctx_.segment, &reclaim_suspects_);
    if (freed) h->daemon_counters[store::kSlotsReclaimed].fetch_add(freed, std::memory_order_relaxed);
    if (const uint32_t waits = store::ReclaimDeadWaiters(h))
      Log(LogLevel::kNotice, "took back %u wait(s) of an application that died in ccomm_wait: writers on this "
          "node no longer wake it", waits);
  }
  if (now >= next_drops_ns_ && ctx_.transport.ops) {
    // Frames lost before ccommd saw them (its receive thread starved, buffer full):
    // otherwise only a sequence gap would tell, without the reason.
    next_drops_ns_ = now + 100000000ull;
    uint32_t drops = 0;
    if (ctx_.transport.SocketDrops(&drops) == 0) {
      h->daemon_counters[store::kSocketDrops].fetch_add(drops - socket_drops_seen_, std::memory_order_relaxed);
      socket_drops_seen_ = drops;
    }
  }
  const uint64_t other_version = ctx_.handoffs.other_version_frames.load(std::memory_order_relaxed);
  if (other_version != other_version_logged_ && now >= other_version_next_log_ns_) {
    const uint32_t last = ctx_.handoffs.other_version_last.load(std::memory_order_relaxed);
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
  // The next tick (NextTickNs): the earliest instant something below falls due.
  uint64_t due = now + kIdleTickNs;
  if (next_reclaim_ns_ < due) due = next_reclaim_ns_;
  if (ctx_.transport.ops && next_drops_ns_ < due) due = next_drops_ns_;
  if (other_version != other_version_logged_ && other_version_next_log_ns_ < due) due = other_version_next_log_ns_;
  for (uint32_t p = 0; p < ctx_.table.node_count(); ++p) {
    if (!ctx_.table.exchanges(p)) continue;
    store::PeerStats& ps = ctx_.segment.peer(p);
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
    } else if (alive && last + peer_timeout_ns_ + 1 < due) {
      due = last + peer_timeout_ns_ + 1;  // lost then, unless a frame comes first
    }
  }
  SuperviseClock(now);
  ctx_.view.Tick(now);  // this node's summary, rate-limited (system_view_writer.h)
  for (uint32_t id : consumed_) {
    const SignalConfig& s = cfg_->signals[id];
    if (!s.stale_after_ms) continue;
    uint64_t last = ctx_.segment.stats(id).last_rx_ns.load(std::memory_order_relaxed);
    const uint64_t stale_ns = uint64_t{s.stale_after_ms} * 1000000;
    bool fresh = !store::IsStale(last != 0, last < now ? now - last : 0, stale_ns);
    if (fresh_[id] && !fresh) ctx_.segment.stats(id).stale_transitions.fetch_add(1, std::memory_order_relaxed);
    fresh_[id] = fresh;
    if (fresh && last + stale_ns + 1 < due) due = last + stale_ns + 1;  // stale then, unless a value comes
  }
  if (ctx_.view.next_due_ns() < due) due = ctx_.view.next_due_ns();
  if (ptp_.NextDueNs() < due) due = ptp_.NextDueNs();
  const uint64_t by_arrival = ctx_.handoffs.by_arrival_frames.load(std::memory_order_relaxed);
  if (by_arrival != by_arrival_logged_ && by_arrival_next_log_ns_ < due) due = by_arrival_next_log_ns_;
  // The send cycle is supervised every tick (SuperviseSendCycle); nothing else needs a
  // fixed tick: a produced signal's age is read off its newest value (SystemViewWriter).
  const bool fixed = ctx_.handoffs.send_cycle.enabled();
  next_tick_ns_ = fixed || due < now + kTickNs ? now + kTickNs : due;
}

// This board's clock state (ptp_state.h) into its segment, where ccomm_get_clock_state()
// and `ccomm stats` read it, to the receive thread (stale_by="production"), and into
// the log when it changes.
void Supervisor::SuperviseClock(uint64_t now) {
  const bool changed = ptp_.Tick(now);
  store::PeerStats& self = ctx_.segment.peer(self_);
  const uint64_t word = static_cast<uint64_t>(ptp_.state()) | uint64_t{ptp_.port_state()} << 8 | uint64_t{1} << 16;
  self.clock_offset_ns.store(static_cast<uint64_t>(ptp_.offset_ns()), std::memory_order_relaxed);
  self.clock_path_delay_ns.store(static_cast<uint64_t>(ptp_.path_delay_ns()), std::memory_order_relaxed);
  self.clock_state.store(word, std::memory_order_release);
  ctx_.handoffs.PublishSelfClock(ptp_.state() == ptp::ClockState::kSynced, platform::RealtimeOffsetNs());
  const uint64_t by_arrival = ctx_.handoffs.by_arrival_frames.load(std::memory_order_relaxed);
  if (by_arrival != by_arrival_logged_ && now >= by_arrival_next_log_ns_) {
    Log(LogLevel::kNotice, "%llu frame(s) with stale_by=\"production\" values judged by their arrival: this "
        "board's clock (%s) or the sender's is not synced, or no current summary of the sender",
        static_cast<unsigned long long>(by_arrival - by_arrival_logged_), ptp::ClockStateName(ptp_.state()));
    by_arrival_logged_ = by_arrival;
    by_arrival_next_log_ns_ = now + 10000000000ull;
  }
  if (changed) LogClockChange();
  // After the clock's own line: the send cycle's re-alignment follows from it.
  SuperviseSendCycle(now, ptp_.state() == ptp::ClockState::kSynced);
}

void Supervisor::LogClockChange() {
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
