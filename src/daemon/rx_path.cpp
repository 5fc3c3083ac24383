// SPDX-License-Identifier: Apache-2.0
// Receive path: validate a frame completely, account it to its peer, store its entries.
// Anything malformed or unexpected is counted and dropped; nothing is half-applied.
#include <errno.h>
#include <time.h>

#include "common/platform.h"
#include "daemon/daemon.h"

namespace ccomm {

void Daemon::HandleFrame(const uint8_t* buf, size_t len, uint64_t now) {
  wire::FrameHeader h;
  if (wire::DecodeHeader(buf, len, &h) != wire::DecodeError::kOk) {
    Count(store::kFramesBad);
    return;
  }
  // Authenticate before any field is trusted (the decode above only checked bounds).
  if (!auth_.Accept(buf, len, h.flags)) {
    Count(store::kFramesAuthFailed);
    return;
  }
  if (h.sender >= peers_rx_.size() || h.sender == self_ || !peers_tx_[h.sender].active) {
    Count(store::kFramesUnknownSender);
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
  uint32_t ahead = h.seq - pr.expected;  // modulo 2^32
  if (!pr.seen || ahead == 0) {
    pr.seen = true;
    pr.expected = h.seq + 1;
  } else if (ahead < 0x80000000u) {
    ps.frames_lost.fetch_add(ahead, std::memory_order_relaxed);
    pr.expected = h.seq + 1;
  } else if (h.send_time_ns > pr.last_send_ns ||
             (now - pr.last_rx_ns > peer_timeout_ns_ && h.send_time_ns <= now - pr.last_rx_ns)) {
    // A lower seq sent later than anything seen: the peer's ccommd restarted. Or both went
    // back after a silence longer than the sender's clock is old: the board rebooted in
    // the meantime. (A frame that is merely late, even after a silence, was sent on an
    // older clock than that: it must not roll the values back.)
    // Its value sequence numbers may restart too.
    Log(LogLevel::kNotice, "peer '%s' restarted (frame seq %u, expected %u)",
        cfg_->nodes[h.sender].name.c_str(), h.seq, pr.expected);
    for (size_t i = 0; i < last_rx_seq_.size(); ++i)
      if (cfg_->signals[i].producer == h.sender) last_rx_seq_[i] = 0;
    pr.expected = h.seq + 1;
  } else {
    ps.frames_reordered.fetch_add(1, std::memory_order_relaxed);  // duplicate or late
  }
  if (h.send_time_ns > pr.last_send_ns) pr.last_send_ns = h.send_time_ns;
  pr.last_rx_ns = now;
  ps.frames_rx.fetch_add(1, std::memory_order_relaxed);
  ps.last_seq.store(h.seq, std::memory_order_relaxed);
  ps.last_rx_ns.store(now, std::memory_order_release);
  ps.last_latency_ns.store(now - h.send_time_ns, std::memory_order_relaxed);
  if (!ps.alive.exchange(1, std::memory_order_acq_rel))
    Log(LogLevel::kNotice, "peer '%s' up", cfg_->nodes[h.sender].name.c_str());
  if (h.flags & wire::kFlagHeartbeat) ps.heartbeats_rx.fetch_add(1, std::memory_order_relaxed);

  wire::EntryIterator it(buf, h);
  wire::EntryView e;
  bool stored = false;
  while (it.Next(&e)) {
    if (e.signal >= segment_.signal_count()) {
      Count(store::kEntriesUnknownSignal);
      continue;
    }
    const store::SignalDirectoryEntry& d = segment_.dir(e.signal);
    const SignalConfig& sc = cfg_->signals[e.signal];
    if (!(d.flags & store::kSigConsumedHere) || sc.producer != h.sender) {
      Count(store::kFramesNotForUs);
      continue;
    }
    bool is_event = (d.flags & store::kSigEvent) != 0;
    if (e.type != d.type || e.count != d.count || e.value_len != d.value_bytes ||
        ((e.flags & wire::kEntryEvent) != 0) != is_event) {
      Count(store::kEntriesWrongType);
      continue;
    }
    uint64_t& last = last_rx_seq_[e.signal];
    if (last && e.seq <= last) continue;  // duplicate or older than what we have
    store::SignalStats& ss = segment_.stats(e.signal);
    // Gaps mean lost values only where every value is sent (events, event-driven states).
    if (last && e.seq > last + 1 && (is_event || sc.period_us == 0))
      ss.lost.fetch_add(e.seq - last - 1, std::memory_order_relaxed);
    last = e.seq;
    wire::ValueToHost(e.type, e.value, rx_value_, e.count);
    store::StoreResult r =
        is_event ? store::RingWrite(segment_.ring(e.signal), rx_value_, e.seq, e.source_time_ns, now)
                 : store::StateWrite(segment_.state(e.signal), rx_value_, e.seq, e.source_time_ns, now);
    if (r != store::StoreResult::kOk) {
      ss.write_errors.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    ss.rx.fetch_add(1, std::memory_order_relaxed);
    ss.last_rx_ns.store(now, std::memory_order_relaxed);
    stored = true;
  }
  // Counted last, with release: whoever sees a frame in frames_rx (acquire) also sees
  // all its entries applied (tests and `ccomm stats` snapshots rely on that).
  Count(store::kFramesRx, std::memory_order_release);
  if (stored) segment_.NotifyRx();
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
      HandleFrame(rx_buf_, static_cast<size_t>(n), platform::MonotonicNs());
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
