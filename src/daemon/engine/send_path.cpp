// SPDX-License-Identifier: Apache-2.0
// The send part (send_path.h): woken at once by a client's doorbell (event-driven
// signals), or at the next periodic/heartbeat deadline; batches everything due for one
// peer into one frame.
#include "daemon/engine/send_path.h"

#include <errno.h>
#include <string.h>

#include "common/platform.h"

namespace ccomm {

int SendPath::OpenStreams(const SystemConfig& cfg, uint32_t self, TransportKind kind, bool force_udp,
                          std::vector<PeerAddress>* groups, std::string* error) {
  cfg_ = &cfg;
  self_ = self;
  heartbeat_ns_ = uint64_t{cfg.network.heartbeat_ms} * 1000000;
  // main() pings the service manager's watchdog only while the send loop advances: an
  // idle loop must turn at least four times per watchdog interval.
  idle_sleep_ns_ = watchdog_ns_ && watchdog_ns_ / 4 < heartbeat_ns_ ? watchdog_ns_ / 4 : heartbeat_ns_;
  const size_t n = cfg.signals.size(), m = cfg.nodes.size();
  const bool multicast = ctx_.table.multicast();
  // A reload (same nodes): each stream's frame numbers go on where they were, so the
  // peers count no loss and see no restart.
  std::vector<uint32_t> seqs;
  if (peers_tx_.size() == m + 1)
    for (const PeerTx& p : peers_tx_) seqs.push_back(p.seq);
  peers_tx_ = std::vector<PeerTx>(m + 1);  // + the group stream
  for (size_t p = 0; p < seqs.size(); ++p) peers_tx_[p].seq = seqs[p];
  periodic_.clear();
  senders_.clear();
  group_tx_ = static_cast<uint32_t>(m);
  consumers_.assign(n, {});
  for (size_t i = 0; i < n; ++i) {
    const SignalConfig& s = cfg.signals[i];
    if (s.producer != self) continue;
    for (uint32_t c : s.consumers) {
      if (c == self) continue;
      // Multicast fan-out: once, to our group, whatever the number of consumers.
      if (!multicast) consumers_[i].push_back(c);
      else if (consumers_[i].empty()) consumers_[i].push_back(group_tx_);
    }
    if (!consumers_[i].empty() && s.period_us) periodic_.push_back(static_cast<uint32_t>(i));
  }
  const NodeConfig& me = cfg.nodes[self];
  bool any_consumer = false;
  for (uint32_t p = 0; p < m; ++p) {
    PeerTx& pt = peers_tx_[p];
    if (!ctx_.table.exchanges(p)) continue;
    TransportKind pk = force_udp ? TransportKind::kUdp : cfg.nodes[p].transport;
    if (pk != kind) {
      *error = "node '" + me.name + "' uses " + (kind == TransportKind::kRaw ? "raw" : "udp") +
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
    // Multicast fan-out: a node joins the groups of the nodes it consumes from, and only
    // those (a producer's group carries all its data, for every consumer). A peer that
    // consumes from us hears our group; one that only produces for us does not join it,
    // so our heartbeats go to it directly (PreparedSignals::direct_stream).
    pt.sends = ctx_.table.direct_stream(p);
    pt.learns_station = ctx_.table.learns_station(p, kind == TransportKind::kRaw && !cfg.nodes[p].has_mac);
    if (pt.sends) senders_.push_back(p);
    if (multicast && ctx_.table.receives_from(p)) groups->push_back(GroupAddressFor(cfg.network, p, kind));
    if (ctx_.table.sends_to(p)) any_consumer = true;
  }
  if (multicast && ctx_.table.exchanges_any()) {
    // Every node's summary goes to the summary group, which every node with a socket
    // joins: any board sees the whole system (ccomm stats --all), not only its peers.
    if (cfg.network.summary_ms != 0) groups->push_back(GroupAddressFor(cfg.network, kSummaryGroup, kind));
  }
  if (multicast && any_consumer) {  // our own group: our data and, when idle, heartbeats
    PeerTx& g = peers_tx_[group_tx_];
    g.sends = true;
    g.dest = wire::kDestAll;
    g.addr = GroupAddressFor(cfg.network, self, kind);
    g.writer = wire::FrameWriter(g.buf, sizeof g.buf);
    senders_.push_back(group_tx_);
  }
  senders_.shrink_to_fit();
  return 0;
}

void SendPath::Prepare(bool adopted, bool keep_sequences) {
  adopted_ = adopted;
  prepared_ = ctx_.table.signals();
  const uint32_t n = ctx_.segment.signal_count();
  // A reload that kept the segment: each state's last value sent stays known, so values
  // written while the threads were stopped still leave (CatchUp) or count as coalesced.
  std::vector<uint64_t> last_sent;
  if (keep_sequences && tx_signals_.size() == n)
    for (const TxSignal& t : tx_signals_) last_sent.push_back(t.last_seq);
  due_ns_.assign(n, 0);
  fwd_cursors_.assign(n, store::RingCursor());
  step_states_.clear();
  large_pending_.clear();
  large_pending_.reserve(n);  // at most one entry per signal and round
  tx_state_.assign(n, store::StateView());
  tx_signals_.assign(n, TxSignal());
  for (uint32_t id = 0; id < n; ++id) {
    const store::SignalDirectoryEntry& d = ctx_.segment.dir(id);
    const PreparedSignals::Signal& ps = prepared_[id];
    if (ps.is_event && ps.forwarded) {
      // Resume where the previous ccommd stopped: queued events are still sent.
      fwd_cursors_[id].next = store::RingForwardCursor(ctx_.segment.ring(id));
    }
    if (!ps.forwarded) continue;
    if (!ps.is_event) tx_state_[id] = ctx_.segment.state(id);
    TxSignal& t = tx_signals_[id];
    if (!last_sent.empty()) t.last_seq = last_sent[id];
    t.state = tx_state_[id];
    t.prefix = ps.prefix;
    t.tx = &ctx_.segment.stats(id).tx;
    t.fast = !ps.is_event && d.value_bytes == 8 && wire::FrameWriter::IsWordPrefix(ps.prefix) &&
             consumers_[id].size() == 1 && !ps.large;
    if (t.fast) t.peer = &peers_tx_[consumers_[id][0]];
  }
  PrepareCatchUp();
}

void SendPath::StartPeriods(uint64_t now) {
  for (uint32_t id : periodic_) due_ns_[id] = now;
}

void SendPath::BeginFrame(uint32_t peer, uint64_t now, uint8_t flags) {
  PeerTx& p = peers_tx_[peer];
  wire::FrameHeader h;
  h.flags = flags | ctx_.auth.frame_flags();  // kFlagAuth: the writer keeps room for the tag
  h.sender = static_cast<uint16_t>(self_);
  h.dest = p.dest;
  h.config_hash = cfg_->hash;
  h.seq = p.seq;  // advanced only when the frame is really sent
  h.send_time_ns = now;
  p.writer.Begin(h);
  p.open = true;
}

void SendPath::FlushPeer(uint32_t peer) {
  PeerTx& p = peers_tx_[peer];
  if (!p.open) return;
  size_t len = p.writer.Finish();
  p.open = false;
  if (len == 0) return;  // nothing in it (a data frame is never empty)
  if (ctx_.auth.enabled()) {
    ctx_.auth.Sign(p.buf, len, p.buf + len);
    len += wire::kAuthTagSize;
  }
  p.seq++;
  int r = flush_launch_tai_ ? ctx_.transport.SendAt(p.addr, p.buf, len, flush_launch_tai_)  // send on the cycle
                            : ctx_.transport.Send(p.addr, p.buf, len);
  p.last_tx_ns = platform::MonotonicNs();  // also on failure: a dead link must not busy-loop
  if (r != 0) {
    Count(ctx_.segment, store::kSendErrors);
    return;
  }
  Count(ctx_.segment, store::kFramesTx);
  // Per-peer counts are for unicast streams; a group frame is counted once, in frames_tx.
  if (peer != group_tx_) ctx_.segment.peer(peer).frames_tx.fetch_add(1, std::memory_order_relaxed);
}

// A heartbeat-only stream to a raw peer without mac= goes to the station its frames come
// from (ThreadHandoffs::peer_station); false until one came.
bool SendPath::KnowsStation(uint32_t peer) {
  const uint64_t station = ctx_.handoffs.peer_station[peer].load(std::memory_order_relaxed);
  if (station == 0) return false;
  for (int i = 0; i < 6; ++i) peers_tx_[peer].addr.mac[i] = static_cast<uint8_t>(station >> (8 * (5 - i)));
  return true;
}

// Inline in CollectSignal: per signal, the common case is one store into an open frame.
__attribute__((always_inline)) inline void SendPath::AddEntry(uint32_t id, const store::SignalDirectoryEntry& d,
                                                              uint8_t flags, const store::SlotMeta& m,
                                                              const void* value, uint64_t now) {
  if (prepared_[id].large) {  // fragments, in frames of their own (SendFragments)
    SendFragments(id, d, flags, m, value, now);
    ctx_.segment.stats(id).tx.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const uint64_t prefix = prepared_[id].prefix;  // the entry's fixed fields, checked and encoded once (the table)
  for (uint32_t peer : consumers_[id]) {
    PeerTx& p = peers_tx_[peer];
    if (p.open && p.writer.AddPrepared(prefix, static_cast<uint32_t>(m.value_seq), m.source_time_ns, value,
                                       d.value_bytes))
      continue;
    for (int attempt = 0; attempt < 2; ++attempt) {
      if (p.open) FlushPeer(peer);  // full: send what we have and start a new frame
      BeginFrame(peer, now, 0);
      if (p.writer.AddPrepared(prefix, static_cast<uint32_t>(m.value_seq), m.source_time_ns, value,
                               d.value_bytes))
        break;
    }
  }
  std::atomic<uint64_t>& tx = ctx_.segment.stats(id).tx;  // this thread is its only writer: no lock
  tx.store(tx.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

// AddEntry for the rarer paths in other files (send_catch_up.cpp): AddEntry stays inline here.
__attribute__((noinline)) void SendPath::AddEntryCold(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags,
                                                      const store::SlotMeta& m, const void* value, uint64_t now) {
  AddEntry(id, d, flags, m, value, now);
}

// The common case (TxSignal::fast: a state, one int64/double, one stream) in a small
// function of its own, so that it saves and restores few registers; every rarer case
// (no frame open or full, a damaged copy, values to catch up) calls out of line.
void SendPath::CollectSignal(uint32_t id, uint64_t now, bool periodic) {
  TxSignal& s = tx_signals_[id];
  if (!s.fast) return CollectSignalSlow(id, now, periodic);
  // A local copy: the acquire loads below would make the compiler reload it from `s`.
  const store::StateView sv = s.state;
  const uint64_t version = store::StateVersion(sv);
  // Event-driven: send each new value once. Periodic: send the last value every period.
  // (No test of version 0 here: `forwarded` is then 0 too, or the read below finds kNever.)
  if (!periodic && version == store::StateForwarded(sv)) return;
  // m and word never leave this function by address: they stay in registers.
  store::SlotMeta m;
  uint64_t word;
  const store::StoreResult r = store::StateReadCopies(sv, &word, &m, 8);  // verifies the copy's check
  if (__builtin_expect(r != store::StoreResult::kOk, 0)) return TxReadFailed(id, r);  // never forwarded
  store::MarkStateForwarded(sv, version);
  if (!periodic) {
    const uint64_t last = s.last_seq;
    if (__builtin_expect(m.value_seq <= last, 0)) return;  // sent already: see CollectSignalSlow
    // Behind the writer: the value goes out after the round's loop, with the older ones
    // still in its slots (send_catch_up.cpp). As in CollectSignalSlow.
    if (__builtin_expect(m.value_seq > last + 1 && (last || !adopted_), 0)) return DeferCatchUp(id);
  }
  s.last_seq = m.value_seq;
  PeerTx& p = *s.peer;
  const uint32_t seq = static_cast<uint32_t>(m.value_seq);
  if (__builtin_expect(p.open && p.writer.AddWord(s.prefix, seq, m.source_time_ns, word), 1)) {
    s.tx->store(s.tx->load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);  // its only writer
    return;
  }
  AddEntryOutOfLine(id, m.value_seq, m.source_time_ns, word, now);  // no frame open, or it is full (counts tx)
}

__attribute__((noinline, cold)) void SendPath::TxReadFailed(uint32_t id, store::StoreResult r) {
  if (r == store::StoreResult::kCorrupt) ctx_.segment.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
}

__attribute__((noinline)) void SendPath::AddEntryOutOfLine(uint32_t id, uint64_t value_seq, uint64_t source_time_ns,
                                                           uint64_t word, uint64_t now) {
  store::SlotMeta m;  // AddEntry uses these two of it
  m.value_seq = value_seq;
  m.source_time_ns = source_time_ns;
  AddEntry(id, ctx_.segment.dir(id), 0, m, &word, now);
}

void SendPath::CollectSignalSlow(uint32_t id, uint64_t now, bool periodic) {
  if (prepared_[id].large && !sending_large_) {  // sent after the round's small entries
    large_pending_.push_back({id, periodic});
    return;
  }
  const store::SignalDirectoryEntry& d = ctx_.segment.dir(id);
  store::SlotMeta m;
  if (d.flags & store::kSigEvent) {
    store::RingView ring = ctx_.segment.ring(id);
    store::RingCursor& cur = fwd_cursors_[id];
    for (uint32_t i = 0; i < d.queue_depth; ++i) {  // bounded: at most one ring's worth
      const store::StoreResult r = store::RingRead(ring, &cur, tx_value_, &m, now);
      if (r == store::StoreResult::kCorrupt) {  // damaged in shared memory: never forwarded
        ctx_.segment.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      if (r != store::StoreResult::kOk) break;
      AddEntry(id, d, wire::kEntryEvent, m, tx_value_, now);
    }
    store::SetRingForwardCursor(ring, cur.next);
    return;
  }
  const store::StateView& sv = tx_state_[id];  // resolved once (Prepare)
  uint64_t version = store::StateVersion(sv);
  // Event-driven: send each new value once. Periodic: send the last value every period.
  if (version == 0 || (!periodic && version == store::StateForwarded(sv))) return;
  const store::StoreResult r = store::StateRead(sv, tx_value_, &m);
  if (r == store::StoreResult::kCorrupt) ctx_.segment.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
  if (r != store::StoreResult::kOk) return;  // a damaged copy is never forwarded
  store::MarkStateForwarded(sv, version);
  uint64_t& last = tx_signals_[id].last_seq;
  // Sent already: the read may return the inline copy of a value whose writer has not
  // raised `latest` yet (state_slot.h), so `forwarded` stays one behind it and the next
  // round finds the same value again (also the first round after a reload, which keeps
  // last_seq: Prepare). A state's values only grow in number within a segment.
  if (!periodic && m.value_seq <= last) return;
  // Values are numbered from 1 in a segment this ccommd created, so values replaced before
  // the first one sent count too; after re-adoption the predecessor is unknown.
  if (!periodic && (last || !adopted_) && m.value_seq > last + 1) {
    if (!prepared_[id].large) return DeferCatchUp(id);  // as in CollectSignal
    const uint64_t gone = CatchUp(id, d, last, m.value_seq, now);  // fragments: never in a step's frame
    if (gone) ctx_.segment.stats(id).coalesced.fetch_add(gone, std::memory_order_relaxed);
  }
  last = m.value_seq;
  AddEntry(id, d, 0, m, tx_value_, now);
}


void SendPath::SendLargeValues(uint64_t now) {
  sending_large_ = true;  // CollectSignal sends now instead of queueing
  for (const LargePending& p : large_pending_) CollectSignal(p.id, now, p.periodic);
  sending_large_ = false;
  large_pending_.clear();
}

void SendPath::SendFragments(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags,
                             const store::SlotMeta& m, const void* value, uint64_t now) {
  const size_t part = wire::FrameWriter::MaxFragmentPart(ctx_.auth.enabled());
  const uint8_t* bytes = static_cast<const uint8_t*>(value);
  for (uint32_t peer : consumers_[id]) {
    PeerTx& p = peers_tx_[peer];
    FlushPeer(peer);  // the round's small entries leave first, in their own frame
    for (size_t off = 0; off < d.value_bytes; off += part) {
      const size_t len = d.value_bytes - off < part ? d.value_bytes - off : part;
      BeginFrame(peer, now, 0);
      // Cannot fail: the arguments follow the signal's directory entry, and a part of
      // MaxFragmentPart bytes fits an empty frame (with room for the tag).
      p.writer.AddFragment(static_cast<uint16_t>(id), d.type, flags, static_cast<uint16_t>(d.count),
                           static_cast<uint32_t>(m.value_seq), m.source_time_ns, static_cast<uint32_t>(off),
                           bytes + off, len);
      FlushPeer(peer);
    }
  }
}

void SendPath::RunTx() {
  const NodeConfig& self = cfg_->nodes[self_];
  store::SegmentHeader* h = ctx_.segment.header();
  std::atomic<uint64_t>* dirty = ctx_.segment.dirty_words();
  const uint32_t signal_count = ctx_.segment.signal_count();
  const uint32_t words = (signal_count + 63) / 64;
  const uint64_t spin_ns = uint64_t{self.realtime.spin_us} * 1000;

  while (ctx_.handoffs.running.load(std::memory_order_relaxed)) {
    ctx_.handoffs.tx_loops.fetch_add(1, std::memory_order_relaxed);
    uint32_t snapshot = h->tx_doorbell.load(std::memory_order_acquire);
    uint64_t now = platform::MonotonicNs();
    const uint32_t steps_before = h->steps_done.load(std::memory_order_acquire);
    for (uint32_t w = 0; w < words; ++w) {
      uint64_t bits = dirty[w].exchange(0, std::memory_order_acq_rel);
      while (bits) {
        uint32_t b = static_cast<uint32_t>(__builtin_ctzll(bits));
        bits &= bits - 1;
        uint32_t id = w * 64 + b;
        // Periodic signals leave on their period only (not early with another write).
        if (id < signal_count && !consumers_[id].empty() && !cfg_->signals[id].period_us)
          CollectSignal(id, now, false);
      }
    }
    SettleSteps(steps_before, now);
    // Idle, the loop wakes once per heartbeat (or more often if the service watchdog
    // needs it to advance sooner, see idle_sleep_ns_).
    uint64_t next_deadline = now + idle_sleep_ns_;
    // send on the cycle: periodic signals are due at instants of the grid and taken one
    // lead early; the round's frames then carry the earliest instant taken.
    const bool on_cycle = ctx_.handoffs.send_cycle.enabled();
    if (on_cycle && ctx_.handoffs.send_cycle.generation() != cycle_generation_) PlaceOnCycle(now);
    const uint64_t lead = on_cycle ? ctx_.handoffs.send_cycle.config().lead_ns : 0, reach = now + lead;
    uint64_t cycle_instant = UINT64_MAX;
    for (uint32_t id : periodic_) {
      if (reach >= due_ns_[id]) {
        CollectSignal(id, now, true);
        if (due_ns_[id] < cycle_instant) cycle_instant = due_ns_[id];
        uint64_t period = uint64_t{cfg_->signals[id].period_us} * 1000;
        due_ns_[id] += period;
        if (due_ns_[id] <= reach)  // fell behind: do not burst
          due_ns_[id] = on_cycle ? ctx_.handoffs.send_cycle.Place(now, period) : now + period;
      }
      if (due_ns_[id] - lead < next_deadline) next_deadline = due_ns_[id] - lead;
    }
    if (!large_pending_.empty()) SendLargeValues(now);
    // send on the cycle: only a round with frames to send waits for its instant and counts
    // (periodic signals never written yet leave nothing to send).
    if (on_cycle && cycle_instant != UINT64_MAX) {
      bool frames = false;
      for (uint32_t p : senders_) frames = frames || peers_tx_[p].open;
      if (frames) CycleRound(cycle_instant);
    }
    for (uint32_t p : senders_) {
      PeerTx& pt = peers_tx_[p];
      if (pt.open) {
        FlushPeer(p);
      } else if (now - pt.last_tx_ns >= heartbeat_ns_) {
        if (!pt.learns_station || KnowsStation(p)) {
          BeginFrame(p, now, wire::kFlagHeartbeat);
          FlushPeer(p);
        } else {
          pt.last_tx_ns = now;  // nowhere to send it yet: again a period later
        }
      }
      uint64_t hb_due = pt.last_tx_ns + heartbeat_ns_;
      if (hb_due < next_deadline) next_deadline = hb_due;
    }
    flush_launch_tai_ = 0;  // send on the cycle: the round's launch time ends with it

    // Optional busy-poll window (no syscalls) before sleeping: trades CPU for latency.
    if (spin_ns) {
      uint64_t until = platform::MonotonicNs() + spin_ns;
      while (h->tx_doorbell.load(std::memory_order_acquire) == snapshot && platform::MonotonicNs() < until &&
             platform::MonotonicNs() < next_deadline) {
        platform::CpuRelax();
      }
      if (h->tx_doorbell.load(std::memory_order_acquire) != snapshot) continue;
    }
    now = platform::MonotonicNs();
    if (next_deadline <= now) continue;
    h->tx_sleeping.store(1, std::memory_order_seq_cst);
    platform::FutexWait(&h->tx_doorbell, snapshot, static_cast<int64_t>(next_deadline - now));
    h->tx_sleeping.store(0, std::memory_order_relaxed);
    Count(ctx_.segment, store::kTxWakeups);
  }
}

}  // namespace ccomm
