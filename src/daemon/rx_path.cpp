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
  bool resync = false;
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
    resync = true;
  } else if (d < -kResyncDistance && ++fs.behind >= kResyncAfter) {
    resync = true;  // the stored position is wrong (see kResyncAfter)
  } else {
    if (d >= -kResyncDistance) fs.behind = 0;
    ps.frames_reordered.fetch_add(1, std::memory_order_relaxed);  // duplicate or late
    return;
  }
  if (resync) {
    Log(LogLevel::kNotice, "peer '%s': frame sequence resynchronised (seq %u, expected %u)",
        cfg_->nodes[h.sender].name.c_str(), h.seq, fs.expected);
    // Its value sequence numbers may restart too: rule 6 follows them (readers keep a
    // growing seq, see SignalRx).
    for (size_t i = 0; i < rx_seq_.size(); ++i)
      if (cfg_->signals[i].producer == h.sender) rx_seq_[i].seen = false;
    ResetReassemblers(h.sender);
    fs.last_send_ns = h.send_time_ns;
  }
  fs.behind = 0;
  fs.expected = h.seq + 1;
  if (h.send_time_ns > fs.last_send_ns) fs.last_send_ns = h.send_time_ns;
}

uint64_t Daemon::AcceptValue(uint32_t id, uint32_t seq, bool count_gaps) {
  SignalRx& r = rx_seq_[id];
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

void Daemon::HandleFrame(const uint8_t* buf, size_t len, uint64_t now, const PeerAddress& from) {
  wire::FrameHeader h;
  // One validation pass: entries of the signals this node takes cost one compare each.
  if (wire::DecodeFrame(buf, len, &h, rx_known_.data(), rx_known_.size()) != wire::DecodeError::kOk) {
    Count(store::kFramesBad);
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
  if (!ps.alive.exchange(1, std::memory_order_acq_rel))
    Log(LogLevel::kNotice, "peer '%s' up", cfg_->nodes[h.sender].name.c_str());
  if (h.flags & wire::kFlagHeartbeat) ps.heartbeats_rx.fetch_add(1, std::memory_order_relaxed);

  // One compare per entry tells a good one (RxSignal::prefix); DecodeFrame has already
  // checked every entry's structure, so nothing is validated twice. States go through the
  // single-writer store (ccommd is the only writer of a received signal), counters through
  // plain stores (this thread is their only writer): a small constant per entry.
  wire::EntryRef e = wire::FirstEntry(buf);
  bool stored = false;
  for (uint16_t i = 0; i < h.entry_count; ++i, e = e.next()) {
    if (e.p[3] & wire::kEntryFragment) {  // part of a large value (large_values.cpp)
      stored |= HandleFragment(h, e, now);
      continue;
    }
    const uint16_t id = e.signal();
    const RxSignal* rs = id < segment_.signal_count() ? &rx_signals_[id] : nullptr;  // sized so (PrepareRxTx)
    if (!rs || rs->prefix != e.prefix() || rs->producer != h.sender) {
      CountBadEntry(id, h);
      continue;
    }
    // Rule 6; the next value in order (the common case) inline, the rest in AcceptValue.
    // Gaps mean lost values only where every value is sent (events, event-driven states).
    SignalRx& sr = rx_seq_[id];
    const uint32_t seq = e.seq();
    uint64_t value_seq;
    if (sr.seen && seq == sr.wire + 1) {
      sr.wire = seq;
      sr.behind = 0;
      value_seq = ++sr.ext;
    } else {
      value_seq = AcceptValue(id, seq, rs->count_gaps);
      if (value_seq == 0) continue;  // duplicate or older than what we have
    }
    const void* value = rx_value_;
    uint64_t word;
    if (rs->one_word) {  // one double or int64: a single byte swap
      word = wire::be::Load<uint64_t>(e.value());
      value = &word;
    } else {
      wire::ValueToHost(e.type(), e.value(), rx_value_, e.count());
    }
    if (rs->is_event) {
      if (store::RingWrite(rs->ring, value, value_seq, e.source_time_ns(), now) != store::StoreResult::kOk) {
        rs->stats->write_errors.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
    } else {
      store::StateWriteSingle(rs->state, value, store::SlotMeta{value_seq, e.source_time_ns(), now});
      AppendHistory(id, value, value_seq, e.source_time_ns(), now);
    }
    rs->stats->rx.store(rs->stats->rx.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    rs->stats->last_rx_ns.store(now, std::memory_order_relaxed);
    stored = true;
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
