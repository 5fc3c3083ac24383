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
  int r = flush_launch_tai_ ? transport_.SendAt(p.addr, p.buf, len, flush_launch_tai_)  // send on the cycle
                            : transport_.Send(p.addr, p.buf, len);
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
  if (large_[id]) {  // fragments, in frames of their own (large_values.cpp)
    SendFragments(id, d, flags, m, value, now);
    segment_.stats(id).tx.fetch_add(1, std::memory_order_relaxed);
    return;
  }
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

// The common case (TxSignal::fast: a state, one int64/double, one stream) in a small
// function of its own, so that it saves and restores few registers; every rarer case
// (no frame open or full, a damaged copy, values to catch up) calls out of line.
void Daemon::CollectSignal(uint32_t id, uint64_t now, bool periodic) {
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
    collected_states_[collected_count_++] = id;  // at most once per signal and round
    const uint64_t last = s.last_seq;
    if (__builtin_expect(m.value_seq > last + 1 && (last || !adopted_), 0))  // as in CollectSignalSlow
      CatchUpAndCount(id, last, m.value_seq, now);
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

__attribute__((noinline, cold)) void Daemon::TxReadFailed(uint32_t id, store::StoreResult r) {
  if (r == store::StoreResult::kCorrupt) segment_.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
}

__attribute__((noinline)) void Daemon::CatchUpAndCount(uint32_t id, uint64_t last_sent, uint64_t newest,
                                                       uint64_t now) {
  const uint64_t gone = CatchUp(id, segment_.dir(id), last_sent, newest, now);
  if (gone) segment_.stats(id).coalesced.fetch_add(gone, std::memory_order_relaxed);
}

__attribute__((noinline)) void Daemon::AddEntryOutOfLine(uint32_t id, uint64_t value_seq, uint64_t source_time_ns,
                                                         uint64_t word, uint64_t now) {
  store::SlotMeta m;  // AddEntry uses these two of it
  m.value_seq = value_seq;
  m.source_time_ns = source_time_ns;
  AddEntry(id, segment_.dir(id), 0, m, &word, now);
}

void Daemon::CollectSignalSlow(uint32_t id, uint64_t now, bool periodic) {
  if (large_[id] && !sending_large_) {  // sent after the round's small entries
    large_pending_.push_back({id, periodic});
    return;
  }
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
  if (!periodic) collected_states_[collected_count_++] = id;  // at most once per signal and round
  uint64_t& last = tx_signals_[id].last_seq;
  // Values are numbered from 1 in a segment this ccommd created, so values replaced before
  // the first one sent count too; after re-adoption the predecessor is unknown.
  if (!periodic && (last || !adopted_) && m.value_seq > last + 1) {
    const uint64_t gone = CatchUp(id, d, last, m.value_seq, now);
    if (gone) segment_.stats(id).coalesced.fetch_add(gone, std::memory_order_relaxed);
  }
  last = m.value_seq;
  AddEntry(id, d, 0, m, tx_value_, now);
}


// An event-driven state sends every value once. When its writer was faster than this
// thread (ccommd descheduled, a late cycle writing two steps back to back), the values
// between the last one sent and the newest are usually still in the cell's slots
// (kStateSlots copies): they go out first, in order, in the same frame, so a recorder or
// history tap downstream gets every value and nothing is coalesced. Bounded by
// kStateSlots - 1 reads; a value already overwritten counts as coalesced.
uint64_t Daemon::CatchUp(uint32_t id, const store::SignalDirectoryEntry& d, uint64_t last_sent, uint64_t newest,
                         uint64_t now) {
  const store::StateView& sv = tx_state_[id];
  const uint64_t first = newest - last_sent - 1 >= store::kStateSlots ? newest - (store::kStateSlots - 1) : last_sent + 1;
  uint64_t gone = first - last_sent - 1;
  for (uint64_t seq = first; seq < newest; ++seq) {
    store::SlotMeta om;
    const store::StoreResult r = store::StateReadTicket(sv, seq - 1, tx_older_, &om);
    if (r == store::StoreResult::kCorrupt) segment_.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
    if (r != store::StoreResult::kOk || om.value_seq != seq) {
      ++gone;
      continue;
    }
    AddEntry(id, d, 0, om, tx_older_, now);
  }
  return gone;
}

// A batch step stores its signals one after another; if one landed while this round was
// collecting, the frames may hold some of its values and the previous step's others. So
// the round waits for steps in progress (bounded), then appends the newer values of every
// state it took to the frames still open (after the older ones, see CatchUp): each step's
// outputs leave together and in order, whatever the timing of ccommd against the writers.
// The common case costs two loads.
void Daemon::SettleSteps(uint32_t steps_before, uint64_t now) {
  store::SegmentHeader* h = segment_.header();
  for (int pass = 0; pass < 8; ++pass) {
    for (int spin = 0; spin < 4096 && h->steps_active.load(std::memory_order_acquire) != 0; ++spin)
      platform::CpuRelax();  // a flush stores a few values: microseconds
    const uint32_t steps_now = h->steps_done.load(std::memory_order_acquire);
    if (steps_now == steps_before) return;
    steps_before = steps_now;
    for (uint32_t i = 0; i < collected_count_; ++i) {
      const uint32_t id = collected_states_[i];
      const store::StateView& sv = tx_state_[id];
      const uint64_t version = store::StateVersion(sv);
      if (version == store::StateForwarded(sv)) continue;  // unchanged since it was taken
      store::SlotMeta m;
      if (store::StateRead(sv, tx_value_, &m) != store::StoreResult::kOk) continue;
      store::MarkStateForwarded(sv, version);
      uint64_t& last = tx_signals_[id].last_seq;
      if (m.value_seq <= last) continue;
      // The newer step's values follow the ones already in the frame (and any between,
      // from the slots): each step leaves whole, in order, and nothing is replaced.
      const uint64_t gone = m.value_seq > last + 1 ? CatchUp(id, segment_.dir(id), last, m.value_seq, now) : 0;
      if (gone) segment_.stats(id).coalesced.fetch_add(gone, std::memory_order_relaxed);
      last = m.value_seq;
      AddEntry(id, segment_.dir(id), 0, m, tx_value_, now);
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
    collected_count_ = 0;
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
    SettleSteps(steps_before, now);
    // Idle, the loop wakes once per heartbeat (or more often if the service watchdog
    // needs it to advance sooner, see idle_sleep_ns_).
    uint64_t next_deadline = now + idle_sleep_ns_;
    // send on the cycle: periodic signals are due at instants of the grid and taken one
    // lead early; the round's frames then carry the earliest instant taken.
    const bool on_cycle = send_cycle_.enabled();
    if (on_cycle && send_cycle_.generation() != cycle_generation_) PlaceOnCycle(now);
    const uint64_t lead = on_cycle ? send_cycle_.config().lead_ns : 0, reach = now + lead;
    uint64_t cycle_instant = UINT64_MAX;
    for (uint32_t id : periodic_) {
      if (reach >= due_ns_[id]) {
        CollectSignal(id, now, true);
        if (due_ns_[id] < cycle_instant) cycle_instant = due_ns_[id];
        uint64_t period = uint64_t{cfg_->signals[id].period_us} * 1000;
        due_ns_[id] += period;
        if (due_ns_[id] <= reach)  // fell behind: do not burst
          due_ns_[id] = on_cycle ? send_cycle_.Place(now, period) : now + period;
      }
      if (due_ns_[id] - lead < next_deadline) next_deadline = due_ns_[id] - lead;
    }
    if (!large_pending_.empty()) SendLargeValues(now);
    if (on_cycle && cycle_instant != UINT64_MAX) CycleRound(cycle_instant);  // send on the cycle
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
    Count(store::kTxWakeups);
  }
}

}  // namespace ccomm
