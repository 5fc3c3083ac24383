// SPDX-License-Identifier: Apache-2.0
// Receive path: validate a frame completely, account it to its peer, store its entries.
// Anything malformed or unexpected is counted and dropped; nothing is half-applied.
#include <errno.h>
#include <time.h>

#include "common/platform.h"
#include "daemon/daemon.h"

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

void Daemon::AccountFrame(const wire::FrameHeader& h, uint64_t now) {
  store::PeerStats& ps = segment_.peer(h.sender);
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

uint64_t Daemon::AcceptValue(uint32_t id, uint32_t seq, bool count_gaps) {
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
      segment_.stats(id).lost.fetch_add(static_cast<uint32_t>(d) - 1, std::memory_order_relaxed);
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
// (large_values.cpp), or one to count and skip. True if it completed a stored value.
bool Daemon::HandleOtherEntry(const wire::FrameHeader& h, const uint8_t* entry, uint64_t now) {
  const wire::EntryRef e{entry};
  if (e.flags() & wire::kEntryFragment) return HandleFragment(h, e, now);
  CountBadEntry(e.signal(), h);
  return false;
}

void Daemon::AppendHistory(uint32_t id, const void* value, uint64_t seq, uint64_t source_ns, uint64_t now) {
  store::RingWrite(history_[id], value, seq, source_ns, now);
}

// Any other signal of a known entry: its value converted to host order, then stored.
// False if the store refused it (an event ring full of unread values: counted).
bool Daemon::StoreEntry(const RxSignal& rs, const uint8_t* entry, const store::SlotMeta& meta) {
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
__attribute__((always_inline)) inline bool Daemon::ApplyEntry(RxSignal& rs, const uint8_t* entry, uint64_t now) {
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

void Daemon::HandleFrame(const uint8_t* buf, size_t len, uint64_t now, const PeerAddress& from) {
  wire::FrameHeader h;
  // One validation pass: entries of the signals this node takes cost one compare each.
  const wire::DecodeError decoded = wire::DecodeFrame(buf, len, &h, rx_known_.data(), rx_known_.size());
  if (decoded != wire::DecodeError::kOk) {
    Count(store::kFramesBad);
    if (decoded == wire::DecodeError::kBadVersion) {  // a board of another ccomm version: say so (supervision)
      other_version_last_.store(uint32_t{buf[4]} << 16 | uint32_t{buf[6]} << 8 | buf[7], std::memory_order_relaxed);
      other_version_frames_.store(other_version_frames_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    }
    return;
  }
  // Authenticate before any field is trusted (the decode above only checked bounds).
  if (!auth_.Accept(buf, len, h.flags)) {
    Count(store::kFramesAuthFailed);
    return;
  }
  if (h.flags & wire::kFlagSummary) {  // a node summary, from any node: not a data frame
    HandleSummary(buf, h, now, from);
    return;
  }
  if (h.sender >= peers_rx_.size() || h.sender == self_ || !peers_tx_[h.sender].active) {
    Count(store::kFramesUnknownSender);
    return;
  }
  if (peers_rx_[h.sender].ipv4 && from.ipv4 != peers_rx_[h.sender].ipv4) {
    Count(store::kFramesWrongSource);  // claims a configured node, sent from elsewhere
    return;
  }
  if (h.dest != self_ && h.dest != wire::kDestAll) {
    Count(store::kFramesNotForUs);  // a broadcast frame meant for another node
    return;
  }
  if (h.config_hash != cfg_->hash) {
    Count(store::kFramesWrongHash);
    if (!wrong_hash_logged_) {  // once: the counter tells how often
      wrong_hash_logged_ = true;
      Log(LogLevel::kWarning, "frames from node '%s' carry config hash %08x, ours is %08x: the boards run "
          "different signals.xml files; their frames are dropped (see ccomm stats)",
          cfg_->nodes[h.sender].name.c_str(), h.config_hash, cfg_->hash);
    }
    return;
  }
  if (auth_.enabled() &&
      replay_[h.sender].Check(h.seq, h.send_time_ns, now, peer_timeout_ns_) == auth::ReplayVerdict::kReplay) {
    Count(store::kFramesReplayed);  // an authentic frame seen before (or older than the window)
    return;
  }
  store::PeerStats& ps = segment_.peer(h.sender);
  PeerRx& pr = peers_rx_[h.sender];
  AccountFrame(h, now);
  pr.last_rx_ns = now;
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
    rx_production_map_ = self_clock_synced_.load(std::memory_order_acquire) != 0 &&
                         view_.SyncedClockOffset(h.sender, now, &sender_offset);
    rx_production_map_ns_ = sender_offset - self_realtime_offset_ns_.load(std::memory_order_relaxed);
    if (!rx_production_map_)
      by_arrival_frames_.store(by_arrival_frames_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
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
  Count(store::kFramesRx, std::memory_order_release);
  if (stored) {
    store::PublishedStoresFence();  // the single-writer stores before the rx_waiters load
    segment_.NotifyRx();
  }
}

void Daemon::RunRx() {
  EnterIoThread("receive");
  while (running_.load(std::memory_order_relaxed)) {
    rx_loops_.fetch_add(1, std::memory_order_relaxed);
    if (!transport_.ops) {  // local-only node: nothing to receive
      platform::SleepNs(uint64_t{static_cast<uint32_t>(opt_.recv_timeout_ms)} * 1000 * 1000);
      continue;
    }
    PeerAddress from;
    ssize_t n = transport_.Recv(rx_buf_, sizeof rx_buf_, &from);
    if (n > 0) {
      HandleFrame(rx_buf_, static_cast<size_t>(n), platform::MonotonicNs(), from);
    } else if (n < 0) {
      const bool bad_frame = n == -EMSGSIZE || n == -ENODATA;  // oversized or empty: junk, not a fault
      if (bad_frame) Count(store::kFramesBad);
      else Count(store::kRecvErrors);
      if (!bad_frame) {
        // e.g. ENETDOWN while the link is down: do not spin.
        platform::SleepNs(10 * 1000 * 1000);
      }
    }
  }
}

}  // namespace ccomm
