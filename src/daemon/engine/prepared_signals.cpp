// SPDX-License-Identifier: Apache-2.0
// The prepared-signals table (prepared_signals.h), built in Daemon::Start().
#include "daemon/engine/prepared_signals.h"

#include "wire/wire.h"

namespace ccomm {

void PreparedSignals::Route(const SystemConfig& cfg, uint32_t self) {
  multicast_ = cfg.network.fanout == Fanout::kMulticast;
  exchanges_.assign(cfg.nodes.size(), 0);
  signals_.assign(cfg.signals.size(), Signal());
  for (size_t i = 0; i < cfg.signals.size(); ++i) {
    const SignalConfig& s = cfg.signals[i];
    signals_[i].producer = s.producer;
    bool consumed_here = false;
    for (uint32_t c : s.consumers) {
      if (s.producer == self && c != self) exchanges_[c] |= kSendsTo;
      if (c == self) consumed_here = true;
    }
    // Heartbeats let the producer supervise us too.
    if (s.producer != self && consumed_here) exchanges_[s.producer] |= kReceivesFrom;
  }
}

bool PreparedSignals::exchanges_any() const {
  for (uint8_t e : exchanges_)
    if (e) return true;
  return false;
}

void PreparedSignals::Resolve(const store::Segment& segment, bool auth) {
  for (uint32_t id = 0; id < signals_.size(); ++id) {
    const store::SignalDirectoryEntry& d = segment.dir(id);
    Signal& s = signals_[id];
    s.is_event = (d.flags & store::kSigEvent) != 0;
    s.forwarded = (d.flags & store::kSigForwarded) != 0;
    s.consumed_here = (d.flags & store::kSigConsumedHere) != 0;
    s.prefix = wire::EntryPrefix(static_cast<uint16_t>(id), d.type, s.is_event ? wire::kEntryEvent : 0,
                                 static_cast<uint16_t>(d.count), d.value_bytes);
    s.large = !wire::FrameWriter::FitsOneFrame(d.value_bytes, auth);
  }
}

}  // namespace ccomm
