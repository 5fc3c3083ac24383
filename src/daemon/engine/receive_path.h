// SPDX-License-Identifier: Apache-2.0
// ccommd's receive part: the receive thread's state and what it does (receive_path.cpp).
// Blocked in the socket, RunRx() validates each frame completely, accounts it to its
// sender (receiver rule 5), stores the entries of the signals this node consumes (rule
// 6), reassembles large values, and hands node summaries to the system view. Anything
// malformed or unexpected is counted and dropped; nothing is half-applied. Everything
// is allocated at start-up; after Daemon::Start() only the receive thread touches this
// object (what it shares: thread_handoffs.h).
#pragma once

#include <cstdint>
#include <vector>

#include "config/config.h"
#include "daemon/clock/peer_clock.h"
#include "daemon/engine/engine_context.h"
#include "daemon/engine/prepared_signals.h"
#include "daemon/engine/system_view_writer.h"
#include "daemon/engine/thread_handoffs.h"
#include "daemon/net/transport.h"
#include "daemon/security/auth.h"
#include "store/segment.h"
#include "wire/fragment.h"
#include "wire/wire.h"

namespace ccomm {

class ReceivePath {
 public:
  explicit ReceivePath(const EngineContext& ctx) : ctx_(ctx) {}
  ReceivePath(const ReceivePath&) = delete;
  ReceivePath& operator=(const ReceivePath&) = delete;

  /// Start-up, once the segment exists and the table is resolved: the signals' receive
  /// records, reassembly buffers, per-peer sequence state; UDP frames of a peer must come
  /// from its configured address (transport `kind`). `recv_timeout_ms`: how long a
  /// local-only node's loop sleeps per turn.
  /// `keep_sequences` (a reload that re-adopted the segment, same nodes and signals): the
  /// peers' frame streams, clocks, replay windows and each signal's last applied value
  /// carry over, so a reload neither counts losses nor lets an old value in again.
  void Prepare(const SystemConfig& cfg, uint32_t self, TransportKind kind, int recv_timeout_ms,
               bool keep_sequences = false);
  /// The receive thread's body; returns once ThreadHandoffs::running is false.
  void RunRx();

 private:
  // Receiver rule 5: one frame sequence per (sender, dest), dest = us or broadcast.
  struct FrameStream {
    bool seen = false;
    uint32_t expected = 0;
    uint32_t behind = 0;        // consecutive frames judged late/duplicate (resync rule)
    uint64_t last_send_ns = 0;  // newest send time seen: a lower seq sent later = restart
  };
  struct PeerRx {
    FrameStream stream[2];      // [0]: frames addressed to us, [1]: broadcast
    uint64_t last_rx_ns = 0;    // our clock at its last accepted frame
    uint32_t ipv4 = 0;          // UDP: the configured source address (network order); 0 = any
    bool learns_station = false;  // its frames' source MAC goes to the send thread (peer_station)
    PeerClock clock;            // its clock's offset floor: frames' queueing delays (peer_clock.h)
  };
  // Receiver rule 6: a signal's last applied value. The wire carries 32-bit sequence
  // numbers; `ext` extends them to 64 bits (serial arithmetic), so readers see a number
  // that only grows, across wrap-around, producer restarts and resynchronisation.
  struct SignalRx {
    bool seen = false;
    uint32_t wire = 0;          // last applied wire seq
    uint32_t behind = 0;        // consecutive values judged not newer (resync rule)
    uint64_t ext = 0;           // its 64-bit extension: the value_seq stored
  };
  // What the receive path needs of a signal, from the table (Prepare): an entry whose
  // first 8 bytes equal `prefix` and whose frame came from `producer` is one this node
  // consumes, of the right type, count and kind. prefix 0 = not consumed.
  // The fields an entry touches come first and together (one record per signal, not one
  // array per field): the receive loop reads one or two cache lines per entry.
  struct alignas(64) RxSignal {  // two cache lines; a power of two indexes with a shift
    uint64_t prefix = 0;
    uint32_t producer = UINT32_MAX;
    uint32_t entry_size = 0;    // bytes of its entries on the wire (header + padded value)
    bool is_event = false;
    bool count_gaps = false;    // every value is sent (events, event-driven states)
    bool one_word = false;      // one 8-byte element (double, int64): converted inline
    bool state_word = false;    // a one_word state: HandleFrame's inline path
    bool history = false;       // a history ring keeps its values (AppendHistory)
    bool by_production = false; // stale_by="production": stamped with its write time when clocks allow
    SignalRx last;              // rule 6: its last applied value
    store::SignalStats* stats = nullptr;
    store::StateView state;
    store::RingView ring;
  };
  // A large value in reassembly (docs/protocol.md, "Large values").
  struct LargeRx {
    std::vector<uint8_t> buf;   // value_bytes, consumed large signals only
    wire::Reassembler reasm;
  };

  void HandleFrame(const uint8_t* buf, size_t len, uint64_t now, const PeerAddress& from);
  void LearnStation(uint32_t peer, const PeerAddress& from);
  __attribute__((noinline)) bool HandleOtherEntry(const wire::FrameHeader& h, const uint8_t* entry, uint64_t now);
  bool ApplyEntry(RxSignal& rs, const uint8_t* entry, uint64_t now);
  __attribute__((noinline)) bool StoreEntry(const RxSignal& rs, const uint8_t* entry, const store::SlotMeta& meta);
  void CountBadEntry(uint16_t signal, const wire::FrameHeader& h);
  void HandleSummary(const uint8_t* buf, const wire::FrameHeader& h, uint64_t now, const PeerAddress& from);
  /// Rule 5 for one accepted-so-far frame: false if it must be dropped as a duplicate.
  void AccountFrame(const wire::FrameHeader& h, uint64_t now);
  /// Rule 6: the value_seq to store for entry seq `seq` of signal `id`, or 0 to drop it.
  uint64_t AcceptValue(uint32_t id, uint32_t seq, bool count_gaps);
  /// A fragment entry: true when it completed a value that was stored.
  bool HandleFragment(const wire::FrameHeader& h, const wire::EntryRef& ref, uint64_t now);
  void ResetReassemblers(uint32_t producer);
  /// History tap (<node history="N">): appends a stored state value to its ring (the
  /// caller checked RxSignal::history). Out of line: the common signal has none.
  __attribute__((noinline)) void AppendHistory(uint32_t id, const void* value, uint64_t seq, uint64_t source_ns,
                                               uint64_t now);
  // stale_by="production" (docs/design.md, "Time"): per frame, the map from the sender's
  // monotonic clock onto ours through the common time base, valid only while both
  // clocks are synced (this board's: ThreadHandoffs::self_clock_synced).
  uint64_t ProductionStamp(uint64_t source_ns, uint64_t arrived) const {
    if (!rx_production_map_) return arrived;  // a clock not synced: the arrival, as without the option
    const int64_t mapped = static_cast<int64_t>(source_ns) + rx_production_map_ns_;
    // Never later than the arrival: an age is never made younger than the local one.
    return mapped <= 0 ? 1 : static_cast<uint64_t>(mapped) < arrived ? static_cast<uint64_t>(mapped) : arrived;
  }

  const EngineContext ctx_;  // what the parts share (Daemon owns it)
  const SystemConfig* cfg_ = nullptr;
  uint32_t self_ = 0;
  uint64_t peer_timeout_ns_ = 0;
  int recv_timeout_ms_ = 0;

  bool any_by_production_ = false;
  bool rx_production_map_ = false;
  int64_t rx_production_map_ns_ = 0;
  bool wrong_hash_logged_ = false;
  bool large_refusal_logged_ = false;

  // Preallocated at start-up.
  std::vector<auth::ReplayWindow> replay_;        // per sender, used only with auth
  std::vector<PeerRx> peers_rx_;
  std::vector<RxSignal> rx_signals_;              // signal -> receive path's view of it
  std::vector<wire::KnownEntry> rx_known_;        // signal -> wire::DecodeFrame's known entry
  std::vector<store::RingView> history_;          // signal -> history ring (ring null: none)
  std::vector<LargeRx> large_rx_;                 // signal -> its reassembly
  alignas(8) uint8_t rx_value_[kMaxValueBytes];
  alignas(8) uint8_t rx_buf_[2048];
};

}  // namespace ccomm
