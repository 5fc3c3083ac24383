// SPDX-License-Identifier: Apache-2.0
// The prepared-signals table: what ccommd's parts read of the configuration, resolved
// once in Daemon::Start() and constant afterwards (every part holds it const): which
// nodes this one exchanges signals with, and per signal the first 8 bytes of its entries
// (signal, type, flags, count, length: wire::EntryPrefix), its producer, its kind and
// whether it travels in fragments. An entry then costs a small constant: the receive
// path recognises a good one by one compare of those 8 bytes, the send path copies them
// instead of re-checking and re-encoding the fields (wire::FrameWriter::AddPrepared).
// The paths build their own per-signal records from it (SendPath::TxSignal,
// ReceivePath::RxSignal: one cache line or two per signal, with the state only that
// thread changes), so that no entry pays an indirection through this table.
#pragma once

#include <cstdint>
#include <vector>

#include "config/config.h"
#include "store/segment.h"

namespace ccomm {

class PreparedSignals {
 public:
  struct Signal {
    uint64_t prefix = 0;         // its entries' first 8 bytes; 0 until Resolve
    uint32_t producer = 0;
    bool forwarded = false;      // produced here and sent (store::kSigForwarded)
    bool consumed_here = false;  // received here from its producer (store::kSigConsumedHere)
    bool is_event = false;
    bool large = false;          // does not fit one frame: sent as fragments (docs/protocol.md)
  };

  /// Step one, from the configuration alone (before the segment or the socket exists, so
  /// that a peer that cannot be reached is refused first): the nodes `self` exchanges
  /// signals with, the fan-out.
  void Route(const SystemConfig& cfg, uint32_t self);
  /// Step two, once the segment exists: each signal as its directory entry describes it;
  /// `auth`: frames carry a tag (less room for a value).
  void Resolve(const store::Segment& segment, bool auth);

  uint32_t signal_count() const { return static_cast<uint32_t>(signals_.size()); }
  uint32_t node_count() const { return static_cast<uint32_t>(exchanges_.size()); }
  const Signal& signal(uint32_t id) const { return signals_[id]; }
  /// The records by signal id, for a path's loops (never resized after Start).
  const Signal* signals() const { return signals_.data(); }
  /// This node sends `node` signals or receives some from it (and heartbeats both ways).
  bool exchanges(uint32_t node) const { return exchanges_[node] != 0; }
  /// `node` consumes a signal this node produces.
  bool sends_to(uint32_t node) const { return (exchanges_[node] & kSendsTo) != 0; }
  /// `node` produces a signal this node consumes.
  bool receives_from(uint32_t node) const { return (exchanges_[node] & kReceivesFrom) != 0; }
  bool exchanges_any() const;
  /// fanout="multicast": one frame stream to this node's group instead of one per peer.
  bool multicast() const { return multicast_; }
  /// Our frames reach `node` on a stream of its own: every peer with unicast fan-out; with
  /// multicast, a peer that does not consume from us (so does not join our group) and only
  /// gets our heartbeats, one per heartbeat period, so that it supervises us.
  bool direct_stream(uint32_t node) const { return exchanges(node) && (!multicast_ || !sends_to(node)); }
  /// That direct stream carries heartbeats only, to a raw peer without mac=: they go to the
  /// station its frames come from (learned by the receive thread, ThreadHandoffs::
  /// peer_station), never to the broadcast address (every board would get them).
  bool learns_station(uint32_t node, bool raw_without_mac) const {
    return raw_without_mac && multicast_ && direct_stream(node);
  }

 private:
  std::vector<Signal> signals_;
  static constexpr uint8_t kSendsTo = 1, kReceivesFrom = 2;
  std::vector<uint8_t> exchanges_;  // by node id: kSendsTo | kReceivesFrom
  bool multicast_ = false;
};

}  // namespace ccomm
