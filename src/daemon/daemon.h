// SPDX-License-Identifier: Apache-2.0
// ccommd's forwarding engine: a send thread (woken by the shared-memory doorbell or
// its periodic/heartbeat deadline), a receive thread (blocked in the socket), and a
// supervision tick on the main thread. Everything is allocated in Start(); the three
// loops never allocate (daemon_alloc_test checks).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "config/config.h"
#include "daemon/auth.h"
#include "daemon/foreign_frames.h"
#include "daemon/peer_clock.h"
#include "daemon/ptp_state.h"
#include "daemon/send_cycle.h"
#include "daemon/system_view_writer.h"
#include "daemon/transport.h"
#include "store/reclaim.h"
#include "store/segment.h"
#include "wire/fragment.h"
#include "wire/wire.h"

namespace ccomm {

struct DaemonOptions {
  std::string config_path = "/etc/ccomm/signals.xml";
  std::string node;            // empty = identify (node_identity.h)
  bool force_udp = false;      // --transport udp: ignore transport="raw" in the file
  bool check_only = false;
  bool which_node = false;     // --which-node: print the node this board is and exit
  bool no_realtime = false;    // --no-rt: skip mlockall / SCHED_FIFO (tests, unprivileged)
  int verbosity = 6;           // LogLevel
  int recv_timeout_ms = 50;
  std::string ptp_socket = "/var/run/ptp4l";  // --ptp-socket; empty: not asked (ptp_state.h)
  bool ptp_socket_given = false;               // --ptp-socket given: <clock socket=> does not apply
  bool clock_config = false;                   // --clock-config: print ptp4l.conf for the node, exit
  int64_t ptp_synced_within_ns = 1000000;      // |offset from master| of a synced slave
};

class Daemon {
 public:
  Daemon() = default;
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;
  ~Daemon();

  /// Creates/adopts the segment, opens the transport, preallocates everything.
  int Start(const SystemConfig& cfg, uint32_t node_id, const DaemonOptions& opt, std::string* error);
  void RunTx();   // send thread body, returns after RequestStop()
  void RunRx();   // receive thread body
  /// Supervision: daemon heartbeat, peer liveness, staleness counters. Call every ~10 ms.
  void Supervise(uint64_t now_ns);
  void SuperviseClock(uint64_t now_ns);  // ptp_state.h, published in ptp_clock.cpp
  /// What SuperviseClock hands the receive thread for stale_by="production": whether this
  /// board's clock is synced, and its CLOCK_REALTIME - CLOCK_MONOTONIC (tests call it too).
  void PublishSelfClock(bool synced, int64_t realtime_offset_ns) {
    self_realtime_offset_ns_.store(realtime_offset_ns, std::memory_order_relaxed);
    self_clock_synced_.store(synced ? 1 : 0, std::memory_order_release);
  }
  void RequestStop();
  /// Detaches from the segment (which stays for the clients: their values go stale).
  void Shutdown();

  /// Loop iteration counters, for the watchdog: both must advance between pings.
  uint64_t tx_loops() const { return tx_loops_.load(std::memory_order_relaxed); }
  uint64_t rx_loops() const { return rx_loops_.load(std::memory_order_relaxed); }
  const store::Segment& segment() const { return segment_; }
  const char* transport_name() const { return transport_.ops ? transport_.ops->name : "none"; }
  bool adopted_segment() const { return adopted_; }

 private:
  // A frame stream this node sends: to one peer (unicast fan-out), or, with
  // fanout="multicast", the one stream to this node's group (index group_tx_).
  struct PeerTx {
    bool active = false;        // we exchange signals with this node
    bool sends = false;         // frames go out on this stream (data and heartbeats)
    uint16_t dest = 0;          // header dest: the peer's id, or wire::kDestAll for the group
    PeerAddress addr;
    uint32_t seq = 0;
    uint64_t last_tx_ns = 0;
    wire::FrameWriter writer{nullptr, 0};
    bool open = false;          // writer holds a begun frame
    uint8_t buf[wire::kMaxFrameSize];
  };
  // Receiver rule 5: one frame sequence per (sender, dest), dest = us or broadcast.
  struct FrameStream {
    bool seen = false;
    uint32_t expected = 0;
    uint32_t behind = 0;        // consecutive frames judged late/duplicate (resync rule)
    uint64_t last_send_ns = 0;  // newest send time seen: a lower seq sent later = restart
  };
  struct PeerRx {
    FrameStream stream[2];      // [0]: frames addressed to us, [1]: broadcast
    uint64_t last_rx_ns = 0;    // our clock at its last accepted frame (receive thread only)
    uint32_t ipv4 = 0;          // UDP: the configured source address (network order); 0 = any
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

  // What the receive path needs of a signal, resolved once in Start() (prepared_signals.cpp):
  // an entry whose first 8 bytes equal `prefix` and whose frame came from `producer` is
  // one this node consumes, of the right type, count and kind. prefix 0 = not consumed.
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
    SignalRx last;              // rule 6: its last applied value (receive thread only)
    store::SignalStats* stats = nullptr;
    store::StateView state;
    store::RingView ring;
  };
  void PrepareRxTx();           // fills rx_signals_, rx_known_, tx_prefix_, tx_state_, tx_signals_
  void CountBadEntry(uint16_t signal, const wire::FrameHeader& h);

  void CollectSignal(uint32_t id, uint64_t now, bool periodic);
  void CollectSignalSlow(uint32_t id, uint64_t now, bool periodic);  // all but TxSignal::fast
  void TxReadFailed(uint32_t id, store::StoreResult r);
  void CatchUpAndCount(uint32_t id, uint64_t last_sent, uint64_t newest, uint64_t now);
  void AddEntryOutOfLine(uint32_t id, uint64_t value_seq, uint64_t source_time_ns, uint64_t word, uint64_t now);
  void SettleSteps(uint32_t steps_before, uint64_t now);
  /// Adds the values of state `id` written after `last_sent` and before the newest one
  /// (value_seq `newest`) that its slots still hold, oldest first; returns how many of
  /// them are gone (replaced before ccommd took them: coalesced).
  uint64_t CatchUp(uint32_t id, const store::SignalDirectoryEntry& d, uint64_t last_sent, uint64_t newest,
                   uint64_t now);
  void AddEntry(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags, const store::SlotMeta& m,
                const void* value, uint64_t now);
  void BeginFrame(uint32_t peer, uint64_t now, uint8_t flags);
  void FlushPeer(uint32_t peer);
  void HandleFrame(const uint8_t* buf, size_t len, uint64_t now, const PeerAddress& from);
  __attribute__((noinline)) bool HandleOtherEntry(const wire::FrameHeader& h, const uint8_t* entry, uint64_t now);
  bool ApplyEntry(RxSignal& rs, const uint8_t* entry, uint64_t now);
  __attribute__((noinline)) bool StoreEntry(const RxSignal& rs, const uint8_t* entry, const store::SlotMeta& meta);
  void HandleSummary(const uint8_t* buf, const wire::FrameHeader& h, uint64_t now, const PeerAddress& from);
  /// Rule 5 for one accepted-so-far frame: false if it must be dropped as a duplicate.
  void AccountFrame(const wire::FrameHeader& h, uint64_t now);
  /// Rule 6: the value_seq to store for entry seq `seq` of signal `id`, or 0 to drop it.
  uint64_t AcceptValue(uint32_t id, uint32_t seq, bool count_gaps);
  /// Real-time set-up of an I/O thread: SCHED_FIFO and CPU from <realtime>, stack prefault.
  void EnterIoThread(const char* name);
  // Large values (large_values.cpp): values that do not fit one frame.
  struct LargeRx {
    std::vector<uint8_t> buf;   // value_bytes, consumed large signals only
    wire::Reassembler reasm;
  };
  struct LargePending {
    uint32_t id;
    bool periodic;
  };
  void InitLargeValues();
  void SendLargeValues(uint64_t now);
  void SendFragments(uint32_t id, const store::SignalDirectoryEntry& d, uint8_t flags, const store::SlotMeta& m,
                     const void* value, uint64_t now);
  /// A fragment entry: true when it completed a value that was stored.
  bool HandleFragment(const wire::FrameHeader& h, const wire::EntryRef& ref, uint64_t now);
  void ResetReassemblers(uint32_t producer);
  /// History tap (<node history="N">): appends a stored state value to its ring (the
  /// caller checked RxSignal::history). Out of line: the common signal has none.
  __attribute__((noinline)) void AppendHistory(uint32_t id, const void* value, uint64_t seq, uint64_t source_ns,
                                               uint64_t now);
  void Count(store::DaemonCounter c, std::memory_order order = std::memory_order_relaxed) {
    segment_.header()->daemon_counters[c].fetch_add(1, order);
  }

  const SystemConfig* cfg_ = nullptr;
  uint32_t self_ = 0;
  DaemonOptions opt_;
  store::Segment segment_;
  int lock_fd_ = -1;  // the node's lock (LockNode), held while this ccommd lives
  bool adopted_ = false;
  Transport transport_;
  auth::FrameAuth auth_;                   // per-frame MAC (off unless auth_key_file is set)
  SystemViewWriter view_;                  // the system view: node summaries out and in (system_view_writer.h)
  ForeignFrameWatch foreign_;              // mismatched boards' frames (foreign_frames.h)
  // Frames of another wire version (docs/protocol.md, Versioning): counted in frames_bad
  // by the receive thread, which also notes the last one's version and sender here; the
  // supervision tick logs them at most every 10 s (no syscall on the receive path).
  // stale_by="production" (docs/design.md, "Time"): this board's clock as the supervision
  // tick last saw it (synced, realtime - monotonic), for the receive thread; and, per
  // frame on the receive thread, the map from the sender's monotonic clock onto ours
  // through the common time base, valid only while both clocks are synced.
  std::atomic<uint32_t> self_clock_synced_{0};
  std::atomic<int64_t> self_realtime_offset_ns_{0};
  bool any_by_production_ = false;
  bool rx_production_map_ = false;
  int64_t rx_production_map_ns_ = 0;
  uint64_t ProductionStamp(uint64_t source_ns, uint64_t arrived) const {
    if (!rx_production_map_) return arrived;  // a clock not synced: the arrival, as without the option
    const int64_t mapped = static_cast<int64_t>(source_ns) + rx_production_map_ns_;
    // Never later than the arrival: an age is never made younger than the local one.
    return mapped <= 0 ? 1 : static_cast<uint64_t>(mapped) < arrived ? static_cast<uint64_t>(mapped) : arrived;
  }
  std::atomic<uint64_t> by_arrival_frames_{0};  // frames with such values judged by arrival (clocks)
  uint64_t by_arrival_logged_ = 0, by_arrival_next_log_ns_ = 0;
  std::atomic<uint64_t> other_version_frames_{0};
  std::atomic<uint32_t> other_version_last_{0};  // version << 16 | sender
  uint64_t other_version_logged_ = 0, other_version_next_log_ns_ = 0;
  std::vector<auth::ReplayWindow> replay_;  // per sender, used only with auth
  std::atomic<bool> running_{false};
  std::atomic<uint64_t> tx_loops_{0}, rx_loops_{0};

  // Preallocated in Start().
  std::vector<PeerTx> peers_tx_;                  // [node id] and, last, the group stream
  std::vector<uint32_t> senders_;                 // indices of peers_tx_ that send
  uint32_t group_tx_ = 0;                         // index of the group stream (multicast fan-out)
  bool fanout_multicast_ = false;
  ptp::Monitor ptp_;              // this board's clock state (supervision thread)
  std::vector<PeerRx> peers_rx_;
  std::vector<std::vector<uint32_t>> consumers_;  // signal -> the streams (peers_tx_) it goes out on
  std::vector<uint32_t> periodic_;                // forwarded periodic signal ids
  std::vector<uint64_t> due_ns_;                  // signal -> next periodic send
  std::vector<store::RingCursor> fwd_cursors_;    // signal -> send-side event cursor
  std::vector<RxSignal> rx_signals_;              // signal -> receive path's view of it
  std::vector<wire::KnownEntry> rx_known_;        // signal -> wire::DecodeFrame's known entry
  std::vector<uint64_t> tx_prefix_;               // signal -> its entries' first 8 bytes
  std::vector<store::StateView> tx_state_;        // signal -> its cell (forwarded states)
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
  std::vector<TxSignal> tx_signals_;              // signal -> its send record
  std::vector<store::RingView> history_;          // signal -> history ring (ring null: none)
  std::vector<uint32_t> collected_states_;        // state signals taken this send round: [0, collected_count_)
  uint32_t collected_count_ = 0;
  std::vector<uint8_t> fresh_;                    // signal -> was fresh at last tick
  std::vector<uint32_t> consumed_;                // ids of signals consumed here
  std::vector<store::SlotSuspect> reclaim_suspects_;  // slot -> what the last scan saw
  uint64_t next_reclaim_ns_ = 0;
  uint64_t next_drops_ns_ = 0;
  uint32_t socket_drops_seen_ = 0;  // the kernel's count for our socket at the last look
  bool wrong_hash_logged_ = false;
  uint64_t heartbeat_ns_ = 0, peer_timeout_ns_ = 0;
  uint64_t idle_sleep_ns_ = 0;  // longest sleep of an idle send loop
  std::vector<uint8_t> large_;                    // signal -> travels in fragments
  std::vector<LargeRx> large_rx_;                 // signal -> its reassembly (receive thread)
  std::vector<LargePending> large_pending_;       // large values due this send round
  bool sending_large_ = false;
  bool large_refusal_logged_ = false;
  // --- send on the cycle (send_cycle.h; send_cycle_daemon.cpp) ---
  void StartSendCycle();                               // Start(), before the capabilities go
  void SuperviseSendCycle(uint64_t now, bool synced);  // supervision tick
  void PlaceOnCycle(uint64_t now);                     // send thread: due_ns_ on the grid
  void CycleRound(uint64_t instant);                   // send thread: launch time, or sleep until it
  int64_t TaiMinusMonotonicNs() const;
  SendCycle send_cycle_;
  uint32_t cycle_generation_ = UINT32_MAX;  // send thread: the grid due_ns_ is on (none yet)
  uint64_t flush_launch_tai_ = 0;   // FlushPeer: this launch time (CLOCK_TAI), 0 = none
  uint64_t cycle_margin_ns_ = 0;    // an instant nearer than this is late (ETF delta + slack)
  int64_t tai_minus_realtime_ns_ = 0;
  uint64_t etf_drops_logged_ = 0, etf_drops_next_log_ns_ = 0;
  // --- end send on the cycle ---
  alignas(8) uint8_t tx_value_[kMaxValueBytes];
  alignas(8) uint8_t tx_older_[kMaxValueBytes];  // CatchUp's copy of an older value
  alignas(8) uint8_t rx_value_[kMaxValueBytes];
  alignas(8) uint8_t rx_buf_[2048];
};

}  // namespace ccomm
