// SPDX-License-Identifier: Apache-2.0
// Send path: woken at once by a client's doorbell (event-driven signals), or at the
// next periodic/heartbeat deadline; batches everything due for one peer into one frame.
#include <errno.h>
#include <string.h>

#include "common/platform.h"
#include "daemon/daemon.h"

namespace ccomm {

void Daemon::BeginFrame(uint32_t peer, uint64_t now, uint8_t flags) {
  PeerTx& p = peers_tx_[peer];
  wire::FrameHeader h;
  h.flags = flags | auth_.frame_flags();  // kFlagAuth: the writer keeps room for the tag
  h.sender = static_cast<uint16_t>(self_);
  h.dest = p.dest;
  h.config_hash = cfg_->hash;
  h.seq = p.seq;  // advanced only when the frame is really sent
  h.send_time_ns = now;
  p.writer.Begin(h);
  p.open = true;
}

void Daemon::FlushPeer(uint32_t peer) {
  PeerTx& p = peers_tx_[peer];
  if (!p.open) return;
  size_t len = p.writer.Finish();
  p.open = false;
  if (len == 0) return;  // nothing in it (a data frame is never empty)
  if (auth_.enabled()) {
    auth_.Sign(p.buf, len, p.buf + len);
    len += wire::kAuthTagSize;
  }
  p.seq++;
  int r = transport_.Send(p.addr, p.buf, len);
  p.last_tx_ns = platform::MonotonicNs();  // also on failure: a dead link must not busy-loop
  if (r != 0) {
    Count(store::kSendErrors);
    return;
  }
  Count(store::kFramesTx);
  // Per-peer counts are for unicast streams; a group frame is counted once, in frames_tx.
  if (peer != group_tx_) segment_.peer(peer).frames_tx.fetch_add(1, std::memory_order_relaxed);
}

// Inline in CollectSignal: per signal, the common case is one store into an open frame.
__attribute__((always_inline)) inline void Daemon::AddEntry(uint32_t id, const store::SignalDirectoryEntry& d,
                                                            uint8_t flags, const store::SlotMeta& m,
                                                            const void* value, uint64_t now) {
  (void)flags;  // encoded in tx_prefix_[id] (kEntryEvent for an event signal)
  const uint64_t prefix = tx_prefix_[id];  // the entry's fixed fields, checked and encoded once (PrepareRxTx)
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
  std::atomic<uint64_t>& tx = segment_.stats(id).tx;  // this thread is its only writer: no lock
  tx.store(tx.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

void Daemon::CollectSignal(uint32_t id, uint64_t now, bool periodic) {
  const store::SignalDirectoryEntry& d = segment_.dir(id);
  store::SlotMeta m;
  if (d.flags & store::kSigEvent) {
    store::RingView ring = segment_.ring(id);
    store::RingCursor& cur = fwd_cursors_[id];
    for (uint32_t i = 0; i < d.queue_depth; ++i) {  // bounded: at most one ring's worth
      const store::StoreResult r = store::RingRead(ring, &cur, tx_value_, &m, now);
      if (r == store::StoreResult::kCorrupt) {  // damaged in shared memory: never forwarded
        segment_.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      if (r != store::StoreResult::kOk) break;
      AddEntry(id, d, wire::kEntryEvent, m, tx_value_, now);
    }
    store::SetRingForwardCursor(ring, cur.next);
    return;
  }
  const store::StateView& sv = tx_state_[id];  // resolved once (PrepareRxTx)
  uint64_t version = store::StateVersion(sv);
  // Event-driven: send each new value once. Periodic: send the last value every period.
  if (version == 0 || (!periodic && version == store::StateForwarded(sv))) return;
  const store::StoreResult r = store::StateRead(sv, tx_value_, &m);
  if (r == store::StoreResult::kCorrupt) segment_.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
  if (r != store::StoreResult::kOk) return;  // a damaged copy is never forwarded
  store::MarkStateForwarded(sv, version);
  if (!periodic) collected_states_.push_back(id);  // preallocated: at most one per signal
  uint64_t& last = last_tx_seq_[id];
  // Values are numbered from 1 in a segment this ccommd created, so values replaced before
  // the first one sent count too; after re-adoption the predecessor is unknown.
  if (!periodic && (last || !adopted_) && m.value_seq > last + 1)
    segment_.stats(id).coalesced.fetch_add(m.value_seq - last - 1, std::memory_order_relaxed);
  last = m.value_seq;
  AddEntry(id, d, 0, m, tx_value_, now);
}


// A batch step stores its signals one after another; if one landed while this round was
// collecting, the frames may hold some of its values and the previous step's others. So
// the round waits for steps in progress (bounded), then brings every state value it took
// up to date in the frames still open: a step's outputs leave together, whatever the
// timing of ccommd against the writers. The common case costs two loads.
void Daemon::SettleSteps(uint32_t steps_before) {
  store::SegmentHeader* h = segment_.header();
  for (int pass = 0; pass < 8; ++pass) {
    for (int spin = 0; spin < 4096 && h->steps_active.load(std::memory_order_acquire) != 0; ++spin)
      platform::CpuRelax();  // a flush stores a few values: microseconds
    const uint32_t steps_now = h->steps_done.load(std::memory_order_acquire);
    if (steps_now == steps_before) return;
    steps_before = steps_now;
    for (uint32_t id : collected_states_) {
      store::StateView sv = segment_.state(id);
      const uint64_t version = store::StateVersion(sv);
      if (version == store::StateForwarded(sv)) continue;  // unchanged since it was taken
      store::SlotMeta m;
      if (store::StateRead(sv, tx_value_, &m) != store::StoreResult::kOk) continue;
      store::MarkStateForwarded(sv, version);
      for (uint32_t peer : consumers_[id]) {
        PeerTx& p = peers_tx_[peer];
        if (p.open)
          p.writer.Rewrite(static_cast<uint16_t>(id), static_cast<uint32_t>(m.value_seq), m.source_time_ns, tx_value_);
      }
      // The value taken first (counted in tx) is replaced in the frame: it and any written
      // between never leave, so they count as coalesced, as in CollectSignal.
      if (m.value_seq > last_tx_seq_[id])
        segment_.stats(id).coalesced.fetch_add(m.value_seq - last_tx_seq_[id], std::memory_order_relaxed);
      last_tx_seq_[id] = m.value_seq;
    }
  }
}

void Daemon::RunTx() {
  const NodeConfig& self = cfg_->nodes[self_];
  EnterIoThread("send");
  store::SegmentHeader* h = segment_.header();
  std::atomic<uint64_t>* dirty = segment_.dirty_words();
  const uint32_t words = (segment_.signal_count() + 63) / 64;
  const uint64_t spin_ns = uint64_t{self.realtime.spin_us} * 1000;

  while (running_.load(std::memory_order_relaxed)) {
    tx_loops_.fetch_add(1, std::memory_order_relaxed);
    uint32_t snapshot = h->tx_doorbell.load(std::memory_order_acquire);
    uint64_t now = platform::MonotonicNs();
    const uint32_t steps_before = h->steps_done.load(std::memory_order_acquire);
    collected_states_.clear();
    for (uint32_t w = 0; w < words; ++w) {
      uint64_t bits = dirty[w].exchange(0, std::memory_order_acq_rel);
      while (bits) {
        uint32_t b = static_cast<uint32_t>(__builtin_ctzll(bits));
        bits &= bits - 1;
        uint32_t id = w * 64 + b;
        // Periodic signals leave on their period only (not early with another write).
        if (id < segment_.signal_count() && !consumers_[id].empty() && !cfg_->signals[id].period_us)
          CollectSignal(id, now, false);
      }
    }
    SettleSteps(steps_before);
    // Idle, the loop wakes once per heartbeat (or more often if the service watchdog
    // needs it to advance sooner, see idle_sleep_ns_).
    uint64_t next_deadline = now + idle_sleep_ns_;
    for (uint32_t id : periodic_) {
      if (now >= due_ns_[id]) {
        CollectSignal(id, now, true);
        uint64_t period = uint64_t{cfg_->signals[id].period_us} * 1000;
        due_ns_[id] += period;
        if (due_ns_[id] <= now) due_ns_[id] = now + period;  // fell behind: do not burst
      }
      if (due_ns_[id] < next_deadline) next_deadline = due_ns_[id];
    }
    for (uint32_t p : senders_) {
      PeerTx& pt = peers_tx_[p];
      if (pt.open) {
        FlushPeer(p);
      } else if (now - pt.last_tx_ns >= heartbeat_ns_) {
        BeginFrame(p, now, wire::kFlagHeartbeat);
        FlushPeer(p);
      }
      uint64_t hb_due = pt.last_tx_ns + heartbeat_ns_;
      if (hb_due < next_deadline) next_deadline = hb_due;
    }

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
    Count(store::kTxWakeups);
  }
}

}  // namespace ccomm
