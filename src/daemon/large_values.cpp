// SPDX-License-Identifier: Apache-2.0
// Large values (docs/protocol.md, "Large values"): a signal whose value does not fit one
// frame is sent as fragment entries, one per frame, after the round's small entries, and
// reassembled on the receiving side before one store write, so readers only ever see
// whole values. Everything is allocated in InitLargeValues(); the send and receive paths
// below never allocate.
#include "common/platform.h"
#include "daemon/daemon.h"

namespace ccomm {

void Daemon::InitLargeValues() {
  const uint32_t n = segment_.signal_count();
  large_.assign(n, 0);
  large_rx_.clear();
  large_rx_.resize(n);
  large_pending_.clear();
  for (uint32_t id = 0; id < n; ++id) {
    const store::SignalDirectoryEntry& d = segment_.dir(id);
    if (wire::FrameWriter::FitsOneFrame(d.value_bytes, auth_.enabled())) continue;
    large_[id] = 1;
    if (d.flags & store::kSigConsumedHere) {
      LargeRx& l = large_rx_[id];
      l.buf.assign(d.value_bytes, 0);
      // Periodic states are sent again unchanged each period: not duplicates.
      l.reasm.Init(l.buf.data(), d.value_bytes, d.period_us != 0 && !(d.flags & store::kSigEvent));
    }
  }
  large_pending_.reserve(n);  // at most one entry per signal and round
}

void Daemon::SendLargeValues(uint64_t now) {
  sending_large_ = true;  // CollectSignal sends now instead of queueing
  for (const LargePending& p : large_pending_) CollectSignal(p.id, now, p.periodic);
  sending_large_ = false;
  large_pending_.clear();
}

void Daemon::SendFragments(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags,
                           const store::SlotMeta& m, const void* value, uint64_t now) {
  const size_t part = wire::FrameWriter::MaxFragmentPart(auth_.enabled());
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

bool Daemon::HandleFragment(const wire::FrameHeader& h, const wire::EntryRef& ref, uint64_t now) {
  wire::EntryView e;
  ref.Read(&e);
  // Not a signal this node takes from this sender: counted as any such entry.
  if (e.signal >= segment_.signal_count() || cfg_->signals[e.signal].producer != h.sender ||
      !(segment_.dir(e.signal).flags & store::kSigConsumedHere)) {
    CountBadEntry(e.signal, h);
    return false;
  }
  const store::SignalDirectoryEntry& d = segment_.dir(e.signal);
  const SignalConfig& sc = cfg_->signals[e.signal];
  store::SignalStats& ss = segment_.stats(e.signal);
  const bool is_event = (d.flags & store::kSigEvent) != 0;
  // A fragment of a signal that travels whole, or that disagrees with its configuration.
  if (!large_[e.signal] || e.type != d.type || e.count != d.count ||
      ((e.flags & wire::kEntryEvent) != 0) != is_event) {
    Count(store::kEntriesWrongType);
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
    if (store::RingWrite(segment_.ring(e.signal), l.reasm.value(), value_seq, l.reasm.source_time_ns(), now) !=
        store::StoreResult::kOk) {
      ss.write_errors.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
  } else {  // ccommd is the only writer of a received state (HandleFrame fences after the frame)
    store::StateWriteSingle(segment_.state(e.signal), l.reasm.value(),
                            store::SlotMeta{value_seq, l.reasm.source_time_ns(), now});
    if (rx_signals_[e.signal].history)
      AppendHistory(e.signal, l.reasm.value(), value_seq, l.reasm.source_time_ns(), now);
  }
  ss.rx.fetch_add(1, std::memory_order_relaxed);
  ss.last_rx_ns.store(now, std::memory_order_relaxed);
  return true;
}

void Daemon::ResetReassemblers(uint32_t producer) {
  for (size_t i = 0; i < large_rx_.size(); ++i)
    if (cfg_->signals[i].producer == producer && !large_rx_[i].buf.empty()) large_rx_[i].reasm.Reset();
}

}  // namespace ccomm
