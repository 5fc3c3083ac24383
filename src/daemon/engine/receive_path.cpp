// SPDX-License-Identifier: Apache-2.0
// The receive part (receive_path.h): validate a frame completely, account it to its
// peer, store its entries. Anything malformed or unexpected is counted and dropped;
// nothing is half-applied.
#include "daemon/engine/receive_path.h"

#include <errno.h>
#include <time.h>

#include "common/platform.h"

namespace ccomm {

namespace {

// Resynchronisation (docs/protocol.md, rules 5 and 6): this many consecutive frames of a
// stream (values of a signal) that all lie more than kResyncDistance behind what was
// accepted mean the stored position is wrong (a forged or corrupted frame jumped it far
// ahead), not that the network reorders: the receiver follows the incoming stream again.
// Reordering and jitter make frames late by tens of frames (netem.sh), never by a
// thousand four times in a row; a frame only a little late is a reordered one.
constexpr uint32_t kResyncAfter = 4;
constexpr int32_t kResyncDistance = 1024;

}  // namespace

void ReceivePath::Prepare(const SystemConfig& cfg, uint32_t self, TransportKind kind, int recv_timeout_ms,
                          bool keep_sequences) {
  cfg_ = &cfg;
  self_ = self;
  recv_timeout_ms_ = recv_timeout_ms;
  peer_timeout_ns_ = uint64_t{cfg.network.peer_timeout_ms} * 1000000;
  const uint32_t n = ctx_.segment.signal_count(), m = static_cast<uint32_t>(cfg.nodes.size());
  keep_sequences = keep_sequences && peers_rx_.size() == m && rx_signals_.size() == n;
  std::vector<PeerRx> old_peers;
  std::vector<auth::ReplayWindow> old_replay;
  std::vector<SignalRx> old_last;
  if (keep_sequences) {
    old_peers.swap(peers_rx_);
    old_replay.swap(replay_);
    for (const RxSignal& r : rx_signals_) old_last.push_back(r.last);
  }
  peers_rx_.assign(m, PeerRx());
  // A floor no frame bears out stands one heartbeat interval at most (peer_clock.h).
  for (PeerRx& pr : peers_rx_) pr.clock.set_confirm_window_ns(uint64_t{cfg.network.heartbeat_ms} * 1000000);
  replay_.assign(m, auth::ReplayWindow());
  if (keep_sequences) {
    for (uint32_t p = 0; p < m; ++p) {
      peers_rx_[p] = old_peers[p];
      peers_rx_[p].ipv4 = 0;  // from this configuration, below
    }
    replay_.swap(old_replay);
  }
  any_by_production_ = false;
  for (uint32_t p = 0; p < m; ++p) {
    // UDP frames must come from the peer's own address (rule 2); raw frames carry no
    // address worth checking (any station can send any source MAC).
    if (ctx_.table.exchanges(p) && kind == TransportKind::kUdp && !cfg.nodes[p].ip.empty())
      platform::ParseIpv4(cfg.nodes[p].ip.c_str(), &peers_rx_[p].ipv4);
    peers_rx_[p].learns_station = ctx_.table.learns_station(p, kind == TransportKind::kRaw && !cfg.nodes[p].has_mac);
  }
  history_.assign(n, store::RingView());
  rx_signals_.assign(n, RxSignal());
  rx_known_.assign(n, wire::KnownEntry());
  large_rx_.clear();
  large_rx_.resize(n);
  for (uint32_t id = 0; id < n; ++id) {
    history_[id] = ctx_.segment.history(id);
    const PreparedSignals::Signal& ps = ctx_.table.signal(id);
    if (!ps.consumed_here) continue;
    const store::SignalDirectoryEntry& d = ctx_.segment.dir(id);
    if (ps.large) {
      LargeRx& l = large_rx_[id];
      l.buf.assign(d.value_bytes, 0);
      // Periodic states are sent again unchanged each period: not duplicates.
      l.reasm.Init(l.buf.data(), d.value_bytes, d.period_us != 0 && !ps.is_event);
    }
    RxSignal& r = rx_signals_[id];
    r.prefix = ps.prefix;
    rx_known_[id] = wire::MakeKnownEntry(ps.prefix, d.type, d.value_bytes);
    r.producer = ps.producer;
    r.is_event = ps.is_event;
    r.count_gaps = ps.is_event || cfg.signals[id].period_us == 0;
    r.one_word = d.count == 1 && d.value_bytes == 8;
    r.state_word = r.one_word && !ps.is_event;
    r.history = history_[id].ring != nullptr;
    r.by_production = !ps.is_event && cfg.signals[id].stale_by == StaleBy::kProduction;
    any_by_production_ |= r.by_production;
    r.entry_size = static_cast<uint32_t>(wire::kEntryHeaderSize + ((d.value_bytes + 7u) & ~7u));
    if (ps.is_event) r.ring = ctx_.segment.ring(id);
    else r.state = ctx_.segment.state(id);
    r.stats = &ctx_.segment.stats(id);
    if (keep_sequences) r.last = old_last[id];
  }
}

void ReceivePath::AccountFrame(const wire::FrameHeader& h, uint64_t now) {
  store::PeerStats& ps = ctx_.segment.peer(h.sender);
  PeerRx& pr = peers_rx_[h.sender];
  FrameStream& fs = pr.stream[h.dest == wire::kDestAll ? 1 : 0];
  const int32_t d = static_cast<int32_t>(h.seq - fs.expected);  // serial arithmetic
  bool resync = false, restarted = false;
  if (!fs.seen || d == 0) {
    fs.seen = true;
  } else if (d > 0) {
    ps.frames_lost.fetch_add(static_cast<uint32_t>(d), std::memory_order_relaxed);
  } else if (h.send_time_ns > fs.last_send_ns ||
             (now - pr.last_rx_ns > peer_timeout_ns_ && h.send_time_ns <= now - pr.last_rx_ns)) {
    // A lower seq sent later than anything seen: the peer's ccommd restarted. Or both went
    // back after a silence longer than the sender's clock is old: the board rebooted in
    // the meantime. (A frame that is merely late, even after a silence, was sent on an
    // older clock than that: it must not roll the values back.)
    resync = restarted = true;
  } else if (d < -kResyncDistance && ++fs.behind >= kResyncAfter) {
    resync = true;  // the stored position is wrong (see kResyncAfter)
  } else {
    if (d >= -kResyncDistance) fs.behind = 0;
    ps.frames_reordered.fetch_add(1, std::memory_order_relaxed);  // duplicate or late
    return;
  }
  if (resync) {
    // The operator's two cases (ccommd(8)): a restart is routine, a jump is not.
    if (restarted)
      Log(LogLevel::kNotice, "peer '%s' restarted (frame seq %u, expected %u)", cfg_->nodes[h.sender].name.c_str(),
          h.seq, fs.expected);
    else
      Log(LogLevel::kNotice, "peer '%s': frame sequence resynchronised (seq %u, expected %u)",
          cfg_->nodes[h.sender].name.c_str(), h.seq, fs.expected);
    // Its value sequence numbers may restart too: rule 6 follows them (readers keep a
    // growing seq, see SignalRx).
    for (size_t i = 0; i < rx_signals_.size(); ++i)
      if (cfg_->signals[i].producer == h.sender) rx_signals_[i].last.seen = false;
    ResetReassemblers(h.sender);
    pr.clock.Reset();  // a rebooted peer's clock starts again: its offset floor is void
    fs.last_send_ns = h.send_time_ns;
  }
  fs.behind = 0;
  fs.expected = h.seq + 1;
  if (h.send_time_ns > fs.last_send_ns) fs.last_send_ns = h.send_time_ns;
}

uint64_t ReceivePath::AcceptValue(uint32_t id, uint32_t seq, bool count_gaps) {
  SignalRx& r = rx_signals_[id].last;
  if (!r.seen) {  // first value, or after the producer restarted: numbering goes on
    r.seen = true;
    r.behind = 0;
    r.ext = r.ext ? r.ext + 1 : seq;
    r.wire = seq;
    return r.ext ? r.ext : (r.ext = 1);
  }
  const int32_t d = static_cast<int32_t>(seq - r.wire);  // serial arithmetic
  if (d > 0) {
    if (d > 1 && count_gaps)
      ctx_.segment.stats(id).lost.fetch_add(static_cast<uint32_t>(d) - 1, std::memory_order_relaxed);
    r.ext += static_cast<uint32_t>(d);
  } else if (d < -kResyncDistance && ++r.behind >= kResyncAfter) {
    r.ext += 1;  // resynchronise (kResyncAfter); nothing counted lost
  } else {
    if (d >= -kResyncDistance) r.behind = 0;
    // Older than what the signal has, or the same value again (a periodic signal's
    // re-send, a duplicate): not new, and a re-send never counts towards resync, so an
    // unchanged value still goes stale.
    return 0;
  }
  r.behind = 0;
  r.wire = seq;
  return r.ext;
}

// An entry that is not a known one of this sender's: a part of a large value
// (HandleFragment), or one to count and skip. True if it completed a stored value.
bool ReceivePath::HandleOtherEntry(const wire::FrameHeader& h, const uint8_t* entry, uint64_t now) {
  const wire::EntryRef e{entry};
  if (e.flags() & wire::kEntryFragment) return HandleFragment(h, e, now);
  CountBadEntry(e.signal(), h);
  return false;
}

void ReceivePath::AppendHistory(uint32_t id, const void* value, uint64_t seq, uint64_t source_ns, uint64_t now) {
  store::RingWrite(history_[id], value, seq, source_ns, now);
}

// Any other signal of a known entry: its value converted to host order, then stored.
// False if the store refused it (an event ring full of unread values: counted).
bool ReceivePath::StoreEntry(const RxSignal& rs, const uint8_t* entry, const store::SlotMeta& meta) {
  const wire::EntryRef e{entry};
  const uint8_t* wire_value = entry + wire::kEntryHeaderSize;  // its prefix says: no fragment
  const void* value = rx_value_;
  uint64_t word;
  if (rs.one_word) {  // one double or int64: a single byte swap
    word = wire::be::Load<uint64_t>(wire_value);
    value = &word;
  } else {
    wire::ValueToHost(e.type(), wire_value, rx_value_, e.count());
  }
  if (rs.is_event) {
    if (store::RingWrite(rs.ring, value, meta.value_seq, meta.source_time_ns, meta.local_time_ns) !=
        store::StoreResult::kOk) {
      rs.stats->write_errors.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    return true;
  }
  store::StateWriteSingle(rs.state, value, meta);
  if (rs.history) AppendHistory(e.signal(), value, meta.value_seq, meta.source_time_ns, meta.local_time_ns);
  return true;
}

// One entry of a signal this node takes from the frame's sender (its prefix matched):
// rule 6, then the store. Inline in HandleFrame's loops. True if a value was stored.
__attribute__((always_inline)) inline bool ReceivePath::ApplyEntry(RxSignal& rs, const uint8_t* entry, uint64_t now) {
  const wire::EntryRef e{entry};
  // Rule 6; the next value in order (the common case) inline, the rest in AcceptValue.
  // Gaps mean lost values only where every value is sent (events, event-driven states).
  SignalRx& sr = rs.last;
  const uint32_t seq = e.seq();
  uint64_t value_seq;
  if (seq == sr.wire + 1 && sr.seen) {
    sr.wire = seq;
    sr.behind = 0;
    value_seq = ++sr.ext;
  } else {
    value_seq = AcceptValue(static_cast<uint32_t>(&rs - rx_signals_.data()), seq, rs.count_gaps);
    if (value_seq == 0) return false;  // duplicate or older than what we have
  }
  const uint64_t source_ns = e.source_time_ns();
  const uint64_t arrived = now;
  if (rs.by_production) now = ProductionStamp(source_ns, arrived);  // the stamp ages count from
  const uint8_t* wire_value = entry + wire::kEntryHeaderSize;  // its prefix says: no fragment
  if (rs.state_word) {  // one double or int64 state (the common signal): inline
    const uint64_t word = wire::be::Load<uint64_t>(wire_value);
    store::StateWriteSingleCopies(rs.state, &word, store::SlotMeta{value_seq, source_ns, now}, 8);
    if (rs.history) {
      const uint64_t copy = word;  // its own address: `word` stays in a register
      AppendHistory(e.signal(), &copy, value_seq, source_ns, now);
    }
  } else if (!StoreEntry(rs, entry, store::SlotMeta{value_seq, source_ns, now})) {
    return false;
  }
  store::SignalStats* const stats = rs.stats;
  stats->rx.store(stats->rx.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  stats->last_rx_ns.store(arrived, std::memory_order_relaxed);
  return true;
}

// Where our heartbeats to this peer go (PreparedSignals::learns_station): the station its
// last accepted frame came from (a board replaced under the same node is followed).
__attribute__((noinline)) void ReceivePath::LearnStation(uint32_t peer, const PeerAddress& from) {
  uint64_t station = 0;
  for (int i = 0; i < 6; ++i) station = station << 8 | from.mac[i];
  std::atomic<uint64_t>& known = ctx_.handoffs.peer_station[peer];
  if ((from.mac[0] & 1) == 0 && known.load(std::memory_order_relaxed) != station)
    known.store(station, std::memory_order_relaxed);
}

void ReceivePath::HandleFrame(const uint8_t* buf, size_t len, uint64_t now, const PeerAddress& from) {
  wire::FrameHeader h;
  // One validation pass: entries of the signals this node takes cost one compare each.
  const wire::DecodeError decoded = wire::DecodeFrame(buf, len, &h, rx_known_.data(), rx_known_.size());
  if (decoded != wire::DecodeError::kOk) {
    Count(ctx_.segment, store::kFramesBad);
    if (decoded == wire::DecodeError::kBadVersion) {  // a board of another ccomm version: say so (supervision)
      ctx_.handoffs.other_version_last.store(uint32_t{buf[4]} << 16 | uint32_t{buf[6]} << 8 | buf[7],
                                         std::memory_order_relaxed);
      ctx_.handoffs.other_version_frames.store(ctx_.handoffs.other_version_frames.load(std::memory_order_relaxed) + 1,
                                           std::memory_order_relaxed);
    }
    return;
  }
  // Authenticate before any field is trusted (the decode above only checked bounds).
  if (!ctx_.auth.Accept(buf, len, h.flags)) {
    Count(ctx_.segment, store::kFramesAuthFailed);
    return;
  }
  if (h.flags & wire::kFlagSummary) {  // a node summary, from any node: not a data frame
    HandleSummary(buf, h, now, from);
    return;
  }
  if (h.sender >= peers_rx_.size() || h.sender == self_ || !ctx_.table.exchanges(h.sender)) {
    Count(ctx_.segment, store::kFramesUnknownSender);
    return;
  }
  if (peers_rx_[h.sender].ipv4 && from.ipv4 != peers_rx_[h.sender].ipv4) {
    Count(ctx_.segment, store::kFramesWrongSource);  // claims a configured node, sent from elsewhere
    return;
  }
  if (h.dest != self_ && h.dest != wire::kDestAll) {
    Count(ctx_.segment, store::kFramesNotForUs);  // a broadcast frame meant for another node
    return;
  }
  if (h.config_hash != cfg_->hash) {
    Count(ctx_.segment, store::kFramesWrongHash);
    if (!wrong_hash_logged_) {  // once: the counter tells how often
      wrong_hash_logged_ = true;
      Log(LogLevel::kWarning, "frames from node '%s' carry config hash %08x, ours is %08x: the boards run "
          "different signals.xml files; their frames are dropped (see ccomm stats)",
          cfg_->nodes[h.sender].name.c_str(), h.config_hash, cfg_->hash);
    }
    return;
  }
  if (ctx_.auth.enabled() &&
      replay_[h.sender].Check(h.seq, h.send_time_ns, now, peer_timeout_ns_) == auth::ReplayVerdict::kReplay) {
    Count(ctx_.segment, store::kFramesReplayed);  // an authentic frame seen before (or older than the window)
    return;
  }
  store::PeerStats& ps = ctx_.segment.peer(h.sender);
  PeerRx& pr = peers_rx_[h.sender];
  AccountFrame(h, now);
  pr.last_rx_ns = now;
  if (__builtin_expect(pr.learns_station, 0)) LearnStation(h.sender, from);
  ps.frames_rx.fetch_add(1, std::memory_order_relaxed);
  ps.last_seq.store(h.seq, std::memory_order_relaxed);
  ps.last_rx_ns.store(now, std::memory_order_release);
  ps.last_latency_ns.store(now - h.send_time_ns, std::memory_order_relaxed);
  // Its values count as arrived when the frame would have without the queueing it met
  // (peer_clock.h): a frame held seconds in our socket does not make its values fresh.
  const uint64_t arrived = now - ClampedQueueDelay(pr.clock.Observe(h.send_time_ns, now), now);
  AccountQueueDelay(ps, pr.clock, now - arrived);
  if (any_by_production_) {  // the sender's clock onto ours, through the common time base
    int64_t sender_offset = 0;
    rx_production_map_ = ctx_.handoffs.self_clock_synced.load(std::memory_order_acquire) != 0 &&
                         ctx_.view.SyncedClockOffset(h.sender, now, &sender_offset);
    rx_production_map_ns_ = sender_offset - ctx_.handoffs.self_realtime_offset_ns.load(std::memory_order_relaxed);
    if (!rx_production_map_)
      ctx_.handoffs.by_arrival_frames.store(ctx_.handoffs.by_arrival_frames.load(std::memory_order_relaxed) + 1,
                                        std::memory_order_relaxed);
  }
  if (!ps.alive.exchange(1, std::memory_order_acq_rel))
    Log(LogLevel::kNotice, "peer '%s' up", cfg_->nodes[h.sender].name.c_str());
  if (h.flags & wire::kFlagHeartbeat) ps.heartbeats_rx.fetch_add(1, std::memory_order_relaxed);

  // DecodeFrame has checked every entry's structure; the leading h.known_entries (the
  // whole frame, usually) it matched with rx_known_, i.e. with the prefix (signal, type,
  // flags, count, length) of a signal this node takes, so for those only the producer is
  // left to check and the size is the signal's. The rest get one compare of their prefix.
  // Anything else (a fragment part, another node's entry in a group frame, a bad one)
  // takes the slow branch. Nothing is validated twice; a small constant per entry.
  const uint8_t* p = buf + wire::kHeaderSize;
  // Locals the compiler can keep in registers across the store's fences (h's address
  // escaped; members may alias the shared memory the stores write).
  RxSignal* const signals = rx_signals_.data();
  const size_t signal_count = rx_signals_.size();
  const uint32_t sender = h.sender, entry_count = h.entry_count, known = h.known_entries;
  bool stored = false;
  uint32_t i = 0;
  for (; i < known; ++i) {
    RxSignal& rs = signals[wire::EntryRef{p}.signal()];  // < signal_count: rx_known_ is as long
    if (rs.producer == sender) stored |= ApplyEntry(rs, p, arrived);
    else stored |= HandleOtherEntry(h, p, arrived);
    p += rs.entry_size;
  }
  for (; i < entry_count; ++i) {
    const wire::EntryRef e{p};
    const uint16_t id = e.signal();
    if (id < signal_count && signals[id].prefix == e.prefix() && signals[id].producer == sender) {
      stored |= ApplyEntry(signals[id], p, arrived);
      p += signals[id].entry_size;
    } else {
      stored |= HandleOtherEntry(h, p, arrived);
      p = e.next().p;
    }
  }
  // Counted last, with release: whoever sees a frame in frames_rx (acquire) also sees
  // all its entries applied (tests and `ccomm stats` snapshots rely on that).
  Count(ctx_.segment, store::kFramesRx, std::memory_order_release);
  if (stored) {
    store::PublishedStoresFence();  // the single-writer stores before the rx_waiters load
    ctx_.segment.NotifyRx();
  }
}

// An entry that is not one this node takes from this sender: says why, in the counters
// (the checks and their order as before the fast path; a group frame carries every
// consumer's entries, so skipping those of signals not consumed here is normal).
void ReceivePath::CountBadEntry(uint16_t signal, const wire::FrameHeader& h) {
  if (signal >= ctx_.segment.signal_count()) {
    Count(ctx_.segment, store::kEntriesUnknownSignal);
    return;
  }
  const PreparedSignals::Signal& s = ctx_.table.signal(signal);
  if (s.producer != h.sender) {
    Count(ctx_.segment, store::kFramesNotForUs);  // the sender does not produce it: not a valid entry
    return;
  }
  if (!s.consumed_here) {
    if (h.dest != wire::kDestAll || !ctx_.table.multicast()) Count(ctx_.segment, store::kFramesNotForUs);
    return;
  }
  Count(ctx_.segment, store::kEntriesWrongType);  // consumed here from this sender: type, count or kind differ
}

// Large values (docs/protocol.md, "Large values"): the fragments of a value are
// reassembled in its preallocated buffer and stored in one write once whole, so readers
// only ever see whole values.
bool ReceivePath::HandleFragment(const wire::FrameHeader& h, const wire::EntryRef& ref, uint64_t now) {
  wire::EntryView e;
  ref.Read(&e);
  // Not a signal this node takes from this sender: counted as any such entry.
  if (e.signal >= ctx_.segment.signal_count() || cfg_->signals[e.signal].producer != h.sender ||
      !(ctx_.segment.dir(e.signal).flags & store::kSigConsumedHere)) {
    CountBadEntry(e.signal, h);
    return false;
  }
  const store::SignalDirectoryEntry& d = ctx_.segment.dir(e.signal);
  const SignalConfig& sc = cfg_->signals[e.signal];
  store::SignalStats& ss = ctx_.segment.stats(e.signal);
  const bool is_event = (d.flags & store::kSigEvent) != 0;
  // A fragment of a signal that travels whole, or that disagrees with its configuration.
  if (!ctx_.table.signal(e.signal).large || e.type != d.type || e.count != d.count ||
      ((e.flags & wire::kEntryEvent) != 0) != is_event) {
    Count(ctx_.segment, store::kEntriesWrongType);
    ss.fragments_refused.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  LargeRx& l = large_rx_[e.signal];
  uint32_t abandoned = 0;
  const wire::FragmentResult r = l.reasm.Accept(e, &abandoned);
  if (abandoned) ss.values_incomplete.fetch_add(abandoned, std::memory_order_relaxed);
  if (wire::IsRefusal(r)) {
    ss.fragments_refused.fetch_add(1, std::memory_order_relaxed);
    if (!large_refusal_logged_) {  // once: the counter tells how often
      large_refusal_logged_ = true;
      Log(LogLevel::kWarning, "signal '%s' from node '%s': fragment refused (%s, seq %u, offset %u); "
          "further refusals are only counted (fragments_refused in ccomm stats)",
          sc.name.c_str(), cfg_->nodes[h.sender].name.c_str(), wire::FragmentResultName(r), e.seq, e.offset);
    }
    return false;
  }
  if (r != wire::FragmentResult::kComplete) return false;
  // The whole value: rule 6 as for any entry. Values abandoned above are missing from
  // the sequence and counted as lost here, once each.
  const uint64_t value_seq = AcceptValue(e.signal, l.reasm.seq(), is_event || sc.period_us == 0);
  if (value_seq == 0) return false;
  if (is_event) {
    if (store::RingWrite(ctx_.segment.ring(e.signal), l.reasm.value(), value_seq, l.reasm.source_time_ns(), now) !=
        store::StoreResult::kOk) {
      ss.write_errors.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
  } else {  // ccommd is the only writer of a received state (HandleFrame fences after the frame)
    store::StateWriteSingle(ctx_.segment.state(e.signal), l.reasm.value(),
                            store::SlotMeta{value_seq, l.reasm.source_time_ns(), now});
    if (rx_signals_[e.signal].history)
      AppendHistory(e.signal, l.reasm.value(), value_seq, l.reasm.source_time_ns(), now);
  }
  ss.rx.fetch_add(1, std::memory_order_relaxed);
  ss.last_rx_ns.store(now, std::memory_order_relaxed);
  return true;
}

void ReceivePath::ResetReassemblers(uint32_t producer) {
  for (size_t i = 0; i < large_rx_.size(); ++i)
    if (cfg_->signals[i].producer == producer && !large_rx_[i].buf.empty()) large_rx_[i].reasm.Reset();
}

// Node summaries (system_view_writer.h): the refusals count in the daemon counters of the
// same meaning as for data frames.
void ReceivePath::HandleSummary(const uint8_t* buf, const wire::FrameHeader& h, uint64_t now,
                                const PeerAddress& from) {
  switch (ctx_.view.Receive(buf, h, now, from)) {
    case SystemViewWriter::Verdict::kApplied: Count(ctx_.segment, store::kFramesRx, std::memory_order_release); break;
    case SystemViewWriter::Verdict::kOld: Count(ctx_.segment, store::kFramesRx); break;  // a duplicate, like data ones
    case SystemViewWriter::Verdict::kOwn: break;
    case SystemViewWriter::Verdict::kUnknownSender: Count(ctx_.segment, store::kFramesUnknownSender); break;
    case SystemViewWriter::Verdict::kWrongSource: Count(ctx_.segment, store::kFramesWrongSource); break;
    case SystemViewWriter::Verdict::kNotForUs: Count(ctx_.segment, store::kFramesNotForUs); break;
    case SystemViewWriter::Verdict::kWrongHash: Count(ctx_.segment, store::kFramesWrongHash); break;
    case SystemViewWriter::Verdict::kUnknownSignal: Count(ctx_.segment, store::kEntriesUnknownSignal); break;
  }
}

void ReceivePath::RunRx() {
  while (ctx_.handoffs.running.load(std::memory_order_relaxed)) {
    ctx_.handoffs.rx_loops.fetch_add(1, std::memory_order_relaxed);
    if (!ctx_.transport.ops) {  // local-only node: nothing to receive
      // Cut short by a stop or reload where the platform can (SIGUSR2, io_interrupt.cpp).
      platform::SleepNsInterruptible(uint64_t{static_cast<uint32_t>(recv_timeout_ms_)} * 1000 * 1000);
      continue;
    }
    PeerAddress from;
    ssize_t n = ctx_.transport.Recv(rx_buf_, sizeof rx_buf_, &from);
    if (n > 0) {
      HandleFrame(rx_buf_, static_cast<size_t>(n), platform::MonotonicNs(), from);
    } else if (n < 0) {
      const bool bad_frame = n == -EMSGSIZE || n == -ENODATA;  // oversized or empty: junk, not a fault
      if (bad_frame) Count(ctx_.segment, store::kFramesBad);
      else Count(ctx_.segment, store::kRecvErrors);
      if (!bad_frame) {
        // e.g. ENETDOWN while the link is down: do not spin.
        platform::SleepNs(10 * 1000 * 1000);
      }
    }
  }
}

}  // namespace ccomm
