// SPDX-License-Identifier: Apache-2.0
// What the send and receive paths need of each signal, resolved once at start-up, so
// that an entry costs a small constant: the receive path recognises a good entry by one
// compare of its first 8 bytes (signal, type, flags, count, length) and stores it with
// the single-writer store; the send path copies those 8 bytes instead of re-checking and
// re-encoding the fields (wire::FrameWriter::AddPrepared).
#include "common/platform.h"
#include "daemon/daemon.h"

namespace ccomm {

void Daemon::PrepareRxTx() {
  const uint32_t n = segment_.signal_count();
  rx_signals_.assign(n, RxSignal());
  rx_known_.assign(n, wire::KnownEntry());
  tx_prefix_.assign(n, 0);
  tx_state_.assign(n, store::StateView());
  tx_signals_.assign(n, TxSignal());
  for (uint32_t id = 0; id < n; ++id) {
    const store::SignalDirectoryEntry& d = segment_.dir(id);
    const bool is_event = (d.flags & store::kSigEvent) != 0;
    const uint64_t prefix = wire::EntryPrefix(static_cast<uint16_t>(id), d.type,
                                              is_event ? wire::kEntryEvent : 0, static_cast<uint16_t>(d.count),
                                              d.value_bytes);
    if (d.flags & store::kSigForwarded) {
      tx_prefix_[id] = prefix;
      if (!is_event) tx_state_[id] = segment_.state(id);
      TxSignal& t = tx_signals_[id];
      t.state = tx_state_[id];
      t.prefix = prefix;
      t.tx = &segment_.stats(id).tx;
      t.fast = !is_event && d.value_bytes == 8 && wire::FrameWriter::IsWordPrefix(prefix) &&
               consumers_[id].size() == 1 && !large_[id];
      if (t.fast) t.peer = &peers_tx_[consumers_[id][0]];
    }
    if (!(d.flags & store::kSigConsumedHere)) continue;
    RxSignal& r = rx_signals_[id];
    r.prefix = prefix;
    rx_known_[id] = wire::MakeKnownEntry(prefix, d.type, d.value_bytes);
    r.producer = cfg_->signals[id].producer;
    r.is_event = is_event;
    r.count_gaps = is_event || cfg_->signals[id].period_us == 0;
    r.one_word = d.count == 1 && d.value_bytes == 8;
    r.state_word = r.one_word && !is_event;
    r.history = history_[id].ring != nullptr;
    r.by_production = !is_event && cfg_->signals[id].stale_by == StaleBy::kProduction;
    any_by_production_ |= r.by_production;
    r.entry_size = static_cast<uint32_t>(wire::kEntryHeaderSize + ((d.value_bytes + 7u) & ~7u));
    if (is_event) r.ring = segment_.ring(id);
    else r.state = segment_.state(id);
    r.stats = &segment_.stats(id);
  }
}

// An entry that is not one this node takes from this sender: says why, in the counters
// (the checks and their order as before the fast path; a group frame carries every
// consumer's entries, so skipping those of signals not consumed here is normal).
void Daemon::CountBadEntry(uint16_t signal, const wire::FrameHeader& h) {
  if (signal >= segment_.signal_count()) {
    Count(store::kEntriesUnknownSignal);
    return;
  }
  const store::SignalDirectoryEntry& d = segment_.dir(signal);
  if (cfg_->signals[signal].producer != h.sender) {
    Count(store::kFramesNotForUs);  // the sender does not produce it: not a valid entry
    return;
  }
  if (!(d.flags & store::kSigConsumedHere)) {
    if (h.dest != wire::kDestAll || !fanout_multicast_) Count(store::kFramesNotForUs);
    return;
  }
  Count(store::kEntriesWrongType);  // consumed here from this sender: type, count or kind differ
}

}  // namespace ccomm
