// SPDX-License-Identifier: Apache-2.0
// ccommd's send part: the send thread's state and what it does (send_path.cpp). Woken
// at once by a client's doorbell (event-driven signals) or at its next periodic or
// heartbeat deadline, RunTx() collects what changed or is due from the segment and
// batches it into one frame per stream; values too large for a frame follow as
// fragments. Everything is allocated at start-up; after Daemon::Start() only the send
// thread touches this object (what it shares: thread_handoffs.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "config/config.h"
#include "daemon/engine/engine_context.h"
#include "daemon/engine/prepared_signals.h"
#include "daemon/engine/thread_handoffs.h"
#include "daemon/net/transport.h"
#include "daemon/security/auth.h"
#include "store/segment.h"
#include "wire/wire.h"

namespace ccomm {

class SendPath {
 public:
  explicit SendPath(const EngineContext& ctx) : ctx_(ctx) {}
  SendPath(const SendPath&) = delete;
  SendPath& operator=(const SendPath&) = delete;

  /// Start-up, from the configuration (before the segment or the socket exists): a stream
  /// to each node this one exchanges signals with, or with fanout="multicast" the one to
  /// its group, addressed for transport `kind`; which signals go out on which; the groups
  /// this node receives, appended to `groups`. 0, or -EINVAL with `error` (a peer on
  /// another transport, or without a usable address).
  int OpenStreams(const SystemConfig& cfg, uint32_t self, TransportKind kind, bool force_udp,
                  std::vector<PeerAddress>* groups, std::string* error);
  /// Before OpenStreams: the service manager's watchdog interval (0: none), which bounds
  /// an idle send loop's sleep.
  void SetWatchdogInterval(uint64_t ns) { watchdog_ns_ = ns; }
  /// Start-up, once the segment exists and the table is resolved: the signals' send
  /// records, event cursors (resumed in a re-adopted segment), buffers.
  /// `keep_sequences`: a reload that re-adopted the segment with the same signals; what
  /// was last sent of each signal carries over (Daemon::Reconfigure).
  void Prepare(bool adopted, bool keep_sequences = false);
  /// Last of start-up: the periodic signals are due from `now` on.
  void StartPeriods(uint64_t now);
  /// Send on the cycle (send_cycle_daemon.cpp), start-up after the transport is open and
  /// before the capabilities go (SO_TXTIME on CLOCK_TAI needs CAP_NET_ADMIN then): the
  /// schedule from <realtime>, the launch mode from the socket and the qdisc.
  void StartCycle();
  /// The send thread's body; returns once ThreadHandoffs::running is false.
  void RunTx();

 private:
  // A frame stream this node sends: to one peer (unicast fan-out), or, with
  // fanout="multicast", the one stream to this node's group (index group_tx_).
  struct PeerTx {
    bool sends = false;         // frames go out on this stream (data and heartbeats)
    bool learns_station = false;  // heartbeats only, to a learned address (KnowsStation)
    uint16_t dest = 0;          // header dest: the peer's id, or wire::kDestAll for the group
    PeerAddress addr;
    uint32_t seq = 0;
    uint64_t last_tx_ns = 0;
    wire::FrameWriter writer{nullptr, 0};
    bool open = false;          // writer holds a begun frame
    uint8_t buf[wire::kMaxFrameSize];
  };
  // What the send path needs of a signal in one record (one index, one cache line); `fast`:
  // the common case, a forwarded state with one int64/double value going out on one
  // stream (a peer or the group), not in fragments.
  struct alignas(64) TxSignal {
    store::StateView state;
    uint64_t prefix = 0;                         // its entries' first 8 bytes
    std::atomic<uint64_t>* tx = nullptr;         // its `tx` counter (this thread: only writer)
    uint64_t last_seq = 0;                       // last value_seq sent (any path)
    PeerTx* peer = nullptr;                      // fast: the one stream (peers_tx_ is never resized)
    bool fast = false;                           // the case above: CollectSignal's fast path
  };
  struct LargePending {  // a large value due this round (sent after the small entries)
    uint32_t id;
    bool periodic;
  };

  void CollectSignal(uint32_t id, uint64_t now, bool periodic);
  void CollectSignalSlow(uint32_t id, uint64_t now, bool periodic);  // all but TxSignal::fast
  void TxReadFailed(uint32_t id, store::StoreResult r);
  void AddEntryOutOfLine(uint32_t id, uint64_t value_seq, uint64_t source_time_ns, uint64_t word, uint64_t now);
  // Behind the writers (send_catch_up.cpp).
  struct DeferredState {  // a state found more than one value ahead of the last one sent
    uint32_t id = 0;
    uint32_t staged = 0;   // values copied into the staging area (this attempt)
    uint64_t cut = 0;      // its `latest` at the cut
    uint64_t gone = 0;     // values since the last one sent no longer in its slots
    uint64_t corrupt = 0;  // copies that failed their check
    size_t stage_at = 0;   // its first value in stage_bytes_
    uint32_t meta_at = 0;  // and in stage_meta_
  };
  void PrepareCatchUp();
  void WaitForSteps();
  void DeferCatchUp(uint32_t id);
  void SendDeferred(uint64_t now);
  bool StageDeferred();
  void CommitDeferred(uint64_t now);
  void SettleSteps(uint32_t steps_before, uint64_t now);
  /// Adds the values of state `id` written after `last_sent` and before the newest one
  /// (value_seq `newest`) that its slots still hold, oldest first; returns how many of
  /// them are gone (replaced before ccommd took them: coalesced).
  uint64_t CatchUp(uint32_t id, const store::SignalDirectoryEntry& d, uint64_t last_sent, uint64_t newest,
                   uint64_t now);
  void AddEntry(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags, const store::SlotMeta& m,
                const void* value, uint64_t now);
  void AddEntryCold(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags, const store::SlotMeta& m,
                    const void* value, uint64_t now);
  void BeginFrame(uint32_t peer, uint64_t now, uint8_t flags);
  void FlushPeer(uint32_t peer);
  bool KnowsStation(uint32_t peer);
  // Large values (docs/protocol.md, "Large values"): one fragment entry per frame, after
  // the round's small entries.
  void SendLargeValues(uint64_t now);
  void SendFragments(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags, const store::SlotMeta& m,
                     const void* value, uint64_t now);
  // Send on the cycle (send_cycle_daemon.cpp): the periodic signals on the grid of the
  // current alignment clock; before a round's frames go out, its launch time or a sleep.
  void PlaceOnCycle(uint64_t now);
  void CycleRound(uint64_t instant);

  const EngineContext ctx_;  // what the parts share (Daemon owns it)
  const SystemConfig* cfg_ = nullptr;
  uint32_t self_ = 0;
  bool adopted_ = false;                          // a re-adopted segment: the last value sent is unknown
  uint64_t heartbeat_ns_ = 0;
  uint64_t idle_sleep_ns_ = 0;                    // longest sleep of an idle send loop
  uint64_t watchdog_ns_ = 0;                      // the service manager's watchdog interval, 0: none

  // Preallocated at start-up.
  const PreparedSignals::Signal* prepared_ = nullptr;  // ctx_.table.signals()
  std::vector<PeerTx> peers_tx_;                  // [node id] and, last, the group stream
  std::vector<uint32_t> senders_;                 // indices of peers_tx_ that send
  uint32_t group_tx_ = 0;                         // index of the group stream (multicast fan-out)
  std::vector<std::vector<uint32_t>> consumers_;  // signal -> the streams (peers_tx_) it goes out on
  std::vector<uint32_t> periodic_;                // forwarded periodic signal ids
  std::vector<uint64_t> due_ns_;                  // signal -> next periodic send
  std::vector<store::RingCursor> fwd_cursors_;    // signal -> send-side event cursor
  std::vector<store::StateView> tx_state_;        // signal -> its cell (forwarded states)
  std::vector<TxSignal> tx_signals_;              // signal -> its send record
  std::vector<uint32_t> step_states_;             // forwarded small states sent on write (a batch step's kind)
  std::vector<LargePending> large_pending_;       // large values due this send round
  std::vector<DeferredState> deferred_;           // states to catch up this round: [0, deferred_count_)
  uint32_t deferred_count_ = 0;
  std::vector<uint8_t> deferred_mark_;            // signal -> in deferred_ now
  std::vector<uint8_t> stage_bytes_;              // the deferred states' values (kStateSlots each, 8-aligned)
  std::vector<store::SlotMeta> stage_meta_;       // and their metadata
  bool steps_wait_ = true;                        // WaitForSteps waits (no wait timed out since a step ended)
  bool sending_large_ = false;
  // Send on the cycle.
  uint32_t cycle_generation_ = UINT32_MAX;  // the grid due_ns_ is on (none yet)
  uint64_t flush_launch_tai_ = 0;           // FlushPeer: this round's launch time (CLOCK_TAI), 0 = none
  uint64_t cycle_margin_ns_ = 0;            // an instant nearer than this is late (ETF delta + slack)
  alignas(8) uint8_t tx_value_[kMaxValueBytes];
  alignas(8) uint8_t tx_older_[kMaxValueBytes];  // CatchUp's copy of an older value
};

}  // namespace ccomm
