// SPDX-License-Identifier: Apache-2.0
// The system view, ccommd's side: building and sending this node's summary (supervision
// tick), writing the other nodes' into the view (receive thread). See system_view_writer.h and docs/protocol.md, "Node summary".
#include "daemon/engine/system_view_writer.h"

#include <string.h>

#include "common/platform.h"
#include "daemon/clock/ptp_state.h"
#include "store/event_ring.h"
#include "store/freshness.h"
#include "store/state_slot.h"

namespace ccomm {
namespace {

constexpr uint64_t kMs = 1000000;
constexpr uint64_t kMinIntervalNs = 100 * kMs;  // at most one summary frame per 100 ms
constexpr uint64_t kOffIntervalNs = 1000 * kMs; // summaries off: own record refreshed each second

bool SameAddress(const PeerAddress& a, const PeerAddress& b, TransportKind kind) {
  return kind == TransportKind::kRaw ? memcmp(a.mac, b.mac, 6) == 0 : a.ipv4 == b.ipv4 && a.port == b.port;
}

uint32_t AgeMs(uint64_t last, uint64_t now) {
  if (last == 0) return wire::kSummaryNoAge;
  const uint64_t ms = last >= now ? 0 : (now - last) / kMs;
  return ms >= wire::kSummaryNoAge ? wire::kSummaryNoAge - 1 : static_cast<uint32_t>(ms);
}

// A node counts as alive while its newest summary is younger than three of its intervals
// (two lost parts in a row are tolerated) and than its peer timeout.
uint64_t AliveTimeoutNs(uint64_t interval_ns, uint32_t peer_timeout_ms) {
  const uint64_t t = 3 * interval_ns;
  return t > uint64_t{peer_timeout_ms} * kMs ? t : uint64_t{peer_timeout_ms} * kMs;
}

}  // namespace

int SystemViewWriter::Start(const SystemConfig& cfg, uint32_t self, TransportKind kind, bool force_udp,
                      store::Segment* segment, Transport* transport, const auth::FrameAuth* auth, int gid,
                      std::string* error) {
  cfg_ = &cfg;
  self_ = self;
  segment_ = segment;
  transport_ = transport;
  auth_ = auth;
  const uint32_t n = static_cast<uint32_t>(cfg.signals.size()), m = static_cast<uint32_t>(cfg.nodes.size());
  int r = view_.Create(store::View::NameFor(cfg.nodes[self].name), m, n, self, cfg.network.summary_ms, gid, error);
  if (r != 0) return r;
  start_ns_ = platform::MonotonicNs();

  reported_.clear();
  for (uint32_t i = 0; i < n; ++i) {
    const SignalConfig& s = cfg.signals[i];
    Reported rep;
    rep.id = i;
    if (s.producer == self) {
      rep.role = wire::kRoleProduced;
    } else {
      bool consumed = false;
      for (uint32_t c : s.consumers) consumed = consumed || c == self;
      if (!consumed) continue;
      rep.role = wire::kRoleConsumed;
    }
    const store::SignalStats& st = segment->stats(i);
    rep.last_count = rep.role == wire::kRoleProduced ? st.writes.load() : st.rx.load();
    reported_.push_back(rep);
  }
  // Room for the largest produced value, the copy NewestWriteNs reads a stamp with.
  size_t largest = 0;
  for (const Reported& rep : reported_)
    if (rep.role == wire::kRoleProduced && segment->dir(rep.id).value_bytes > largest)
      largest = segment->dir(rep.id).value_bytes;
  scratch_.assign((largest + 7) / 8, 0);
  for (Reported& rep : reported_)  // a re-adopted segment: its values keep their time
    if (rep.role == wire::kRoleProduced) rep.last_write_ns = NewestWriteNs(rep.id);
  const size_t per = wire::kSummaryMaxRecords;
  parts_ = reported_.empty() ? 1 : static_cast<uint32_t>((reported_.size() + per - 1) / per);
  if (cfg.network.summary_ms == 0) {
    interval_ns_ = kOffIntervalNs;
  } else {
    interval_ns_ = uint64_t{cfg.network.summary_ms} * kMs / parts_;
    if (interval_ns_ < kMinIntervalNs) interval_ns_ = kMinIntervalNs;
  }

  dests_.clear();
  senders_.assign(m, SenderState());
  for (uint32_t p = 0; p < m; ++p) {
    const TransportKind pk = force_udp ? TransportKind::kUdp : cfg.nodes[p].transport;
    // UDP summaries must come from the sender's own address, as data frames (rule 2).
    if (pk == TransportKind::kUdp && !cfg.nodes[p].ip.empty()) platform::ParseIpv4(cfg.nodes[p].ip.c_str(), &senders_[p].ipv4);
    if (p == self || pk != kind || cfg.network.summary_ms == 0 || transport->ops == nullptr) continue;
    if (cfg.network.fanout == Fanout::kMulticast) continue;  // one frame to our group, below
    Dest d;
    if (!PeerAddressFor(cfg.network, cfg.nodes[p], kind, &d.addr)) continue;  // unreachable: no summary
    // A raw node without mac= is reached by Ethernet broadcast: every station gets the
    // frame, so it says so (protocol.md, "Node summary"), also when that node is the only one.
    const bool broadcast = kind == TransportKind::kRaw && !cfg.nodes[p].has_mac;
    d.dest = broadcast ? wire::kDestAll : static_cast<uint16_t>(p);
    bool shared = false;
    for (Dest& o : dests_) {
      if (SameAddress(o.addr, d.addr, kind)) {  // broadcast MAC or a shared group: send once to all
        o.dest = wire::kDestAll;
        shared = true;
      }
    }
    if (!shared) dests_.push_back(d);
  }
  if (cfg.network.fanout == Fanout::kMulticast && cfg.network.summary_ms != 0 && transport->ops != nullptr) {
    // Multicast fan-out: once to the summary group, which every node joined (SendPath::OpenStreams).
    Dest d;
    d.addr = GroupAddressFor(cfg.network, kSummaryGroup, kind);
    d.dest = wire::kDestAll;
    dests_.push_back(d);
  }
  next_ns_ = start_ns_;
  cycle_start_ns_ = start_ns_;
  next_part_ = 0;
  return 0;
}

void SystemViewWriter::Snapshot(uint64_t now) {
  const double dt = now > cycle_start_ns_ ? static_cast<double>(now - cycle_start_ns_) : 0;
  for (Reported& rep : reported_) {
    const store::SignalStats& st = segment_->stats(rep.id);
    const uint64_t count = rep.role == wire::kRoleProduced ? st.writes.load(std::memory_order_relaxed)
                                                           : st.rx.load(std::memory_order_relaxed);
    const double rate = dt > 0 ? static_cast<double>(count - rep.last_count) * 1e12 / dt : 0;
    rep.rec.rate_mhz = rate >= 4294967295.0 ? 0xFFFFFFFFu : static_cast<uint32_t>(rate + 0.5);
    rep.last_count = count;
  }
  cycle_start_ns_ = now;
}

// The write time its writer stamped on the newest value of produced signal `id` (its
// local_time_ns), or 0 if none can be read (never written, or being rewritten: the
// caller keeps what it had). Read when a record is built, not sampled per tick, so the
// supervision need not wake while the signal is written (Supervisor::NextTickNs).
uint64_t SystemViewWriter::NewestWriteNs(uint32_t id) {
  store::SlotMeta meta;
  if (segment_->dir(id).flags & store::kSigEvent) {
    const store::RingView ring = segment_->ring(id);
    const uint64_t head = ring.ring->head.load(std::memory_order_acquire);
    for (uint64_t t = head; t > 0 && head - t < 2; --t)  // the newest event, or the one before it if that is mid-write
      if (store::ReadSlot(ring.slot(t - 1), t - 1, ring.value_bytes, scratch_.data(), &meta) == store::CopyResult::kOk)
        return meta.local_time_ns;
    return 0;
  }
  return store::StateRead(segment_->state(id), scratch_.data(), &meta) == store::StoreResult::kOk ? meta.local_time_ns
                                                                                                  : 0;
}

uint32_t SystemViewWriter::Tick(uint64_t now) {
  if (now < next_ns_) return 0;
  next_ns_ = now + interval_ns_;
  if (next_part_ == 0) Snapshot(now);
  const uint32_t part = next_part_;
  next_part_ = (next_part_ + 1) % parts_;

  // This part's node-level head and records, current as of now (rates: the last cycle).
  const store::SegmentHeader* sh = segment_->header();
  wire::SummaryHead& head = head_;
  head.part = static_cast<uint8_t>(part);
  head.parts = static_cast<uint8_t>(parts_);
  head.cycle_ms = static_cast<uint32_t>(interval_ns_ * parts_ / kMs);
  head.uptime_ns = now - start_ns_;
  head.peers_alive = 0;
  head.frames_lost = 0;
  for (uint32_t p = 0; p < cfg_->nodes.size(); ++p) {
    const store::PeerStats& ps = segment_->peer(p);
    if (p != self_ && ps.alive.load(std::memory_order_relaxed)) head.peers_alive |= uint64_t{1} << p;
    head.frames_lost += ps.frames_lost.load(std::memory_order_relaxed);
  }
  head.frames_rx = sh->daemon_counters[store::kFramesRx].load(std::memory_order_relaxed);
  head.frames_tx = sh->daemon_counters[store::kFramesTx].load(std::memory_order_relaxed);
  head.frames_bad = sh->daemon_counters[store::kFramesBad].load(std::memory_order_relaxed);
  head.socket_drops = sh->daemon_counters[store::kSocketDrops].load(std::memory_order_relaxed);
  // This board's clock as the supervision tick published it (Supervisor::SuperviseClock).
  const store::PeerStats& me = segment_->peer(self_);
  const uint64_t clock = me.clock_state.load(std::memory_order_acquire);
  const auto state = static_cast<ptp::ClockState>(clock & 0xFF);
  head.clock_state = static_cast<uint8_t>(clock & 0xFF) < wire::kSummaryClockStates ? static_cast<uint8_t>(clock & 0xFF) : 0;
  const int64_t error = ptp::ClockErrorNs(state, static_cast<uint8_t>(clock >> 8),
                                          static_cast<int64_t>(me.clock_offset_ns.load(std::memory_order_relaxed)),
                                          static_cast<int64_t>(me.clock_path_delay_ns.load(std::memory_order_relaxed)));
  head.clock_error_ns = error < 0 || error >= int64_t{wire::kSummaryNoClockError}
                            ? wire::kSummaryNoClockError  // beyond 4.29 s is no bound worth the name
                            : static_cast<uint32_t>(error);
  head.clock_offset_ns = platform::RealtimeOffsetNs();
  const uint32_t first = part * static_cast<uint32_t>(wire::kSummaryMaxRecords);
  uint32_t end = first + static_cast<uint32_t>(wire::kSummaryMaxRecords);
  if (end > reported_.size()) end = static_cast<uint32_t>(reported_.size());
  for (uint32_t i = first; i < end; ++i) {
    Reported& rep = reported_[i];
    const store::SignalStats& st = segment_->stats(rep.id);
    wire::SummaryRecord& rec = rep.rec;
    rec.signal = static_cast<uint16_t>(rep.id);
    rec.role = rep.role;
    rec.flags = 0;
    if (rep.role == wire::kRoleProduced) {
      rec.lost = st.write_errors.load(std::memory_order_relaxed);
      if (const uint64_t t = NewestWriteNs(rep.id)) rep.last_write_ns = t;
      rec.age_ms = AgeMs(rep.last_write_ns, now);  // 0: never written (kSummaryNoAge)
    } else {
      rec.lost = st.lost.load(std::memory_order_relaxed);
      rec.age_ms = AgeMs(st.last_rx_ns.load(std::memory_order_relaxed), now);
      const uint32_t stale_ms = cfg_->signals[rep.id].stale_after_ms;
      if (store::IsStale(rec.age_ms != wire::kSummaryNoAge, rec.age_ms, stale_ms)) rec.flags |= wire::kRecordStale;
    }
    if (rec.age_ms == wire::kSummaryNoAge) rec.flags |= wire::kRecordNever;
  }
  WriteSelf(head, first, end, now);
  if (cfg_->network.summary_ms == 0) return 0;

  uint32_t sent = 0;
  store::ViewHeader* vh = view_.mutable_header();
  for (Dest& d : dests_) {
    wire::FrameHeader h;
    h.flags = static_cast<uint8_t>(wire::kFlagSummary | auth_->frame_flags());
    h.sender = static_cast<uint16_t>(self_);
    h.dest = d.dest;
    h.config_hash = cfg_->hash;
    h.seq = d.seq++;
    h.send_time_ns = now;
    wire::SummaryWriter w(buf_, sizeof buf_);
    bool ok = w.Begin(h, head);
    for (uint32_t i = first; ok && i < end; ++i) ok = w.Add(reported_[i].rec);
    size_t len = ok ? w.Finish() : 0;
    if (len == 0) continue;  // cannot happen: parts are sized to fit
    if (auth_->enabled()) {
      auth_->Sign(buf_, len, buf_ + len);
      len += wire::kAuthTagSize;
    }
    if (transport_->Send(d.addr, buf_, len) != 0) {
      vh->summaries_send_errors.fetch_add(1, std::memory_order_relaxed);  // e.g. a node's network is down
      continue;
    }
    vh->summaries_tx.fetch_add(1, std::memory_order_relaxed);
    // Every frame on the wire is in frames_tx (as every frame received is in frames_rx),
    // not in the per-peer counters (those are the data streams').
    segment_->header()->daemon_counters[store::kFramesTx].fetch_add(1, std::memory_order_relaxed);
    ++sent;
  }
  return sent;
}

bool SystemViewWriter::SyncedClockOffset(uint32_t node, uint64_t now, int64_t* offset_ns) const {
  store::ViewNodeCopy n;
  if (!view_.is_open() || node == self_ || !view_.ReadNode(node, &n)) return false;
  const uint64_t last = n.w[store::kVwLastRxNs];
  if (last == 0 || (now > last && now - last > n.w[store::kVwTimeoutNs])) return false;
  if (n.w[store::kVwClockState] != static_cast<uint64_t>(ptp::ClockState::kSynced) ||
      n.w[store::kVwClockErrorNs] == wire::kSummaryNoClockError)
    return false;
  *offset_ns = static_cast<int64_t>(n.w[store::kVwClockOffsetNs]);
  return true;
}

void SystemViewWriter::SetHeadWords(uint32_t node, const wire::SummaryHead& head) {
  view_.SetNodeWord(node, store::kVwUptimeNs, head.uptime_ns);
  view_.SetNodeWord(node, store::kVwPeersAlive, head.peers_alive);
  view_.SetNodeWord(node, store::kVwFramesRx, head.frames_rx);
  view_.SetNodeWord(node, store::kVwFramesTx, head.frames_tx);
  view_.SetNodeWord(node, store::kVwFramesBad, head.frames_bad);
  view_.SetNodeWord(node, store::kVwFramesLost, head.frames_lost);
  view_.SetNodeWord(node, store::kVwSocketDrops, head.socket_drops);
  view_.SetNodeWord(node, store::kVwCycleMs, head.cycle_ms);
  view_.SetNodeWord(node, store::kVwClockState, head.clock_state);
  view_.SetNodeWord(node, store::kVwClockErrorNs, head.clock_error_ns);
  view_.SetNodeWord(node, store::kVwClockOffsetNs, static_cast<uint64_t>(head.clock_offset_ns));
}

void SystemViewWriter::WriteSelf(const wire::SummaryHead& head, uint32_t first, uint32_t end, uint64_t now) {
  view_.BeginWrite(self_);
  view_.SetNodeWord(self_, store::kVwLastRxNs, now);
  view_.SetNodeWord(self_, store::kVwTimeoutNs, AliveTimeoutNs(interval_ns_, cfg_->network.peer_timeout_ms));
  SetHeadWords(self_, head);
  for (uint32_t i = first; i < end; ++i) {
    const wire::SummaryRecord& r = reported_[i].rec;
    view_.SetRow(self_, r.signal, r.role, r.flags, r.rate_mhz, r.lost, r.age_ms, now);
  }
  view_.EndWrite(self_);
}

SystemViewWriter::Verdict SystemViewWriter::Receive(const uint8_t* frame, const wire::FrameHeader& h, uint64_t now,
                                        const PeerAddress& from) {
  store::ViewHeader* vh = view_.mutable_header();
  Verdict v = Verdict::kApplied;
  if (h.sender == self_ && senders_[self_].ipv4 && from.ipv4 == senders_[self_].ipv4 && h.dest == wire::kDestAll)
    return Verdict::kOwn;
  if (h.sender >= senders_.size() || h.sender == self_) v = Verdict::kUnknownSender;
  else if (senders_[h.sender].ipv4 && from.ipv4 != senders_[h.sender].ipv4) v = Verdict::kWrongSource;
  else if (h.dest != self_ && h.dest != wire::kDestAll) v = Verdict::kNotForUs;
  else if (h.config_hash != cfg_->hash) v = Verdict::kWrongHash;
  wire::SummaryHead head;
  if (v == Verdict::kApplied) {
    wire::ReadSummaryHead(frame, &head);
    // Every record must name a signal the sender really produces or consumes (same hash,
    // so anything else is a forged or corrupted frame): refused whole, nothing applied.
    for (uint16_t i = 0; i < head.record_count && v == Verdict::kApplied; ++i) {
      wire::SummaryRecord r;
      wire::ReadSummaryRecord(frame, i, &r);
      if (r.signal >= cfg_->signals.size()) {
        v = Verdict::kUnknownSignal;
        break;
      }
      const SignalConfig& s = cfg_->signals[r.signal];
      bool consumer = false;
      for (uint32_t c : s.consumers) consumer = consumer || c == h.sender;
      if (r.role == wire::kRoleProduced ? s.producer != h.sender : !consumer) v = Verdict::kUnknownSignal;
    }
  }
  if (v != Verdict::kApplied) {
    vh->summaries_refused.fetch_add(1, std::memory_order_relaxed);
    return v;
  }
  SenderState& s = senders_[h.sender];
  const uint64_t interval_ns = head.parts ? uint64_t{head.cycle_ms} * kMs / head.parts : 0;
  const uint64_t timeout = AliveTimeoutNs(interval_ns, cfg_->network.peer_timeout_ms);
  // Newer than the last applied one on the sender's clock; or, after a silence longer than
  // the sender's clock is old, a rebooted sender (as receiver rule 5 judges frames).
  const bool newer = h.send_time_ns > s.last_send_ns;
  const bool rebooted = s.last_rx_ns && now - s.last_rx_ns > timeout && h.send_time_ns <= now - s.last_rx_ns;
  if (s.last_rx_ns && !newer && !rebooted) {
    vh->summaries_old.fetch_add(1, std::memory_order_relaxed);
    return Verdict::kOld;
  }
  s.last_send_ns = h.send_time_ns;
  s.last_rx_ns = now;

  const uint32_t node = h.sender;
  store::ViewNodeCopy prev;
  const uint64_t parts_seen = view_.ReadNode(node, &prev) ? prev.w[store::kVwSummaries] : 0;
  view_.BeginWrite(node);
  view_.SetNodeWord(node, store::kVwLastRxNs, now);
  view_.SetNodeWord(node, store::kVwTimeoutNs, timeout);
  view_.SetNodeWord(node, store::kVwSummaries, parts_seen + 1);
  SetHeadWords(node, head);
  for (uint16_t i = 0; i < head.record_count; ++i) {
    wire::SummaryRecord r;
    wire::ReadSummaryRecord(frame, i, &r);
    view_.SetRow(node, r.signal, r.role, r.flags, r.rate_mhz, r.lost, r.age_ms, now);
  }
  view_.EndWrite(node);
  vh->summaries_rx.fetch_add(1, std::memory_order_relaxed);
  return Verdict::kApplied;
}

}  // namespace ccomm
