// SPDX-License-Identifier: Apache-2.0
// Layout of a node's shared-memory segment ("/ccomm.<node>").
//
// ccommd creates the segment from signals.xml; applications only map it and find
// everything they need inside (names, types, offsets), so they never parse XML.
// Invariants:
//   - No pointers inside the segment: every reference is a byte offset from its start,
//     so each process may map it at a different address.
//   - Everything after `state == kReady` is either immutable (header fields, directory,
//     safe values) or accessed only through std::atomic (slots, rings, counters). Hence
//     no torn reads, and TSan sees no plain data race.
//   - Nothing is ever locked: a process killed at any instruction leaves at most one
//     slot marked "being written", which the algorithms skip (state_slot.h,
//     event_ring.h).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace ccomm {
namespace store {

static_assert(std::atomic<uint64_t>::is_always_lock_free, "shared-memory atomics must be lock-free");
static_assert(std::atomic<uint32_t>::is_always_lock_free, "shared-memory atomics must be lock-free");

constexpr uint32_t kSegmentMagic = 0x43435348;  // "CCSH"
constexpr uint32_t kLayoutVersion = 8;
constexpr size_t kCacheLine = 64;
constexpr uint32_t kStateSlots = 4;  // copies per state signal; see state_slot.h
constexpr size_t kNameBytes = 64;

enum SegmentState : uint32_t { kInitializing = 0, kReady = 1, kRetired = 2 };

// Who waits in ccomm_wait(), per process: a process that dies waiting leaves its count
// here, and ccommd takes it back from rx_waiters (reclaim.h, ReclaimDeadWaiters); else
// rx_waiters stays raised and every writer of the node makes a FUTEX_WAKE per write from
// then on. A process that finds no free entry waits counted in rx_waiters only.
constexpr uint32_t kWaiterEntries = 32;
struct WaiterEntry {
  std::atomic<uint32_t> pid;      // 0: free; claimed by CAS, freed by ccommd when the process is gone
  std::atomic<uint32_t> waiting;  // that process's waits in progress (its share of rx_waiters)
};

struct alignas(kCacheLine) SegmentHeader {
  uint32_t magic;
  uint32_t layout_version;
  uint64_t size;               // bytes of the whole segment
  uint32_t config_hash;
  uint32_t node_id;
  uint32_t signal_count;
  uint32_t node_count;
  uint64_t directory_offset;   // SignalDirectoryEntry[signal_count]
  uint64_t node_names_offset;  // char[kNameBytes][node_count]
  uint64_t signal_stats_offset;  // SignalStats[signal_count]
  uint64_t peer_stats_offset;    // PeerStats[node_count]
  uint64_t dirty_offset;         // atomic<uint64_t>[(signal_count + 63) / 64]
  char node_name[kNameBytes];
  std::atomic<uint32_t> state;       // SegmentState
  std::atomic<uint32_t> generation;  // +1 each time a ccommd attaches
  std::atomic<int32_t> daemon_pid;   // 0 when no daemon
  std::atomic<uint64_t> daemon_heartbeat_ns;  // ccommd's CLOCK_MONOTONIC, each supervision tick (<= 100 ms)

  // Send path doorbell: writers of forwarded signals set their dirty bit, bump
  // tx_doorbell and FUTEX_WAKE it only if ccommd said it is about to sleep.
  alignas(kCacheLine) std::atomic<uint32_t> tx_doorbell;
  std::atomic<uint32_t> tx_sleeping;
  // Batch steps (CCOMM_OPEN_BATCH flushes) store several signals one after another:
  // `steps_active` counts flushes storing right now, `steps_done` counts finished ones,
  // so ccommd can tell that a step landed while it was collecting (send_path.cpp, SettleSteps).
  std::atomic<uint32_t> steps_active;
  std::atomic<uint32_t> steps_done;
  // Receive-side notification for ccomm_wait(), touched by writers only while someone
  // waits: a writer publishes (a seq_cst RMW on the signal: `latest` or `published`),
  // then loads rx_waiters; a waiter increments rx_waiters, then compares every signal's
  // change counter with what it saw last. One of the two sees the other (Dekker), so a
  // write is never missed, and writers do not share a line when nobody waits.
  alignas(kCacheLine) std::atomic<uint32_t> rx_doorbell;
  std::atomic<uint32_t> rx_waiters;
  // Apart from the doorbell's line: touched only as a wait begins and ends.
  alignas(kCacheLine) WaiterEntry waiters[kWaiterEntries];

  // Daemon-wide counters (frames rejected by reason etc.), see DaemonStats.
  alignas(kCacheLine) std::atomic<uint64_t> daemon_counters[32];
};

enum DaemonCounter : uint32_t {
  kFramesRx = 0, kFramesTx, kFramesBad, kFramesWrongHash, kFramesUnknownSender,
  kFramesAuthFailed, kFramesReplayed, kFramesNotForUs, kEntriesUnknownSignal,
  kEntriesWrongType, kSendErrors, kTxWakeups, kRecvErrors, kSlotsReclaimed,
  kSocketDrops,  // frames the kernel dropped at ccommd's socket (receive buffer full)
  kFramesWrongSource,  // UDP frames whose source address is not the sender's configured one
  kFramesForeign,  // ccomm frames of another transport, EtherType or UDP port (foreign_frames.h)
  // Send on the cycle (daemon/engine/send_cycle.h): rounds sent on an instant, rounds that woke
  // after theirs, frames the ETF qdisc dropped, and the launch mode (a LaunchMode, not a count).
  kCycleRounds, kCycleLate, kCycleEtfDrops, kCycleLaunch,
  kDaemonCounterCount
};
static_assert(kDaemonCounterCount <= 32, "daemon_counters has 32 entries");

enum SignalFlags : uint32_t {
  kSigEvent = 1u << 0,         // event signal (ring) rather than state (slots)
  kSigProducedHere = 1u << 1,  // this node may write it
  kSigForwarded = 1u << 2,     // produced here and consumed by another node
  kSigConsumedHere = 1u << 3,  // produced elsewhere and consumed here
  kSigHasSafeValue = 1u << 4,
  kSigPeriodic = 1u << 5,      // forwarded on a period, not on every write
};

// Immutable after creation.
struct alignas(8) SignalDirectoryEntry {
  char name[kNameBytes];
  uint32_t id;
  uint32_t flags;          // SignalFlags
  uint8_t type;            // ValueType code
  uint8_t reserved[3];
  uint32_t count;
  uint32_t value_bytes;    // count * element size
  uint32_t slot_bytes;     // bytes of one slot including its header, multiple of 8
  uint32_t producer;       // node id
  uint32_t stale_after_ms;
  uint32_t period_us;
  uint32_t queue_depth;    // events: ring capacity (power of two); states: kStateSlots
  uint64_t data_offset;    // StateCell or EventRing
  uint64_t safe_value_offset;  // value_bytes, rounded to 8; 0 if none
  // History tap (<node history="N">): states received from another node also keep their
  // last N values, in order, in an EventRing (ccommd appends each value it stores), so a
  // recorder sees every value however late it reads. 0 / 0 when the node keeps none.
  uint64_t history_offset;     // EventRing + history_depth slots of slot_bytes
  uint32_t history_depth;      // power of two
  uint32_t reserved2;
};

// Header of every slot (state copy or event), followed by the value rounded up to 8 bytes.
// `seq` protocol (ticket t): 2t+1 while being written, 2t+2 when complete, 0 = free.
// `owner` = (writer pid << 32) | (t & 0xffffffff), stored right after the claim, lets
// ccommd tell a dead writer's slot from a slow one (store/reclaim.h).
struct alignas(8) SlotHeader {
  std::atomic<uint64_t> seq;
  std::atomic<uint64_t> owner;
  std::atomic<uint64_t> value_seq;       // producer's sequence number of the value
  std::atomic<uint64_t> source_time_ns;  // producer's clock at write
  std::atomic<uint64_t> local_time_ns;   // this node's clock when it entered the segment
  std::atomic<uint64_t> check;           // CopyCheck of meta and value (seqlock.h): a copy a
                                         // stray client write damaged is detected, not used
};
static_assert(sizeof(SlotHeader) == 48, "slot header is 6 words");

// Values of at most this many bytes also live in the cell's first cache line (below).
constexpr uint32_t kInlineValueBytes = 16;

// A state cell: three cache lines, then kStateSlots slots (state_slot.h).
// Line 0 is all a reader touches for a small value: `latest` and a copy of the newest
// value under its own seqlock (`inline_seq`), so a hand-off moves one cache line, as a
// bare shared variable does. Writers change line 0 only with plain stores and the one
// CAS that publishes `latest`: who may fill the inline copy is decided on line 1
// (`inline_claim`, a slot header's seq/owner protocol, reclaimed like a slot), which
// readers never touch.
struct alignas(kCacheLine) StateCell {
  std::atomic<uint64_t> latest;       // ticket + 1 of the newest complete copy; 0 = never
  std::atomic<uint64_t> inline_seq;   // 2t+1 while ticket t's value is copied in, 2t+2 complete
  std::atomic<uint64_t> inline_meta[4];  // value_seq, source_time_ns, local_time_ns, check (as SlotHeader)
  std::atomic<uint64_t> inline_value[kInlineValueBytes / 8];
  alignas(kCacheLine) std::atomic<uint64_t> next_ticket;  // claimed tickets
  SlotHeader inline_claim;            // seq/owner only: the writer filling the inline copy
  // ccommd's send side alone, on a line of its own: beside the writers' line it moved
  // that line between the application's core and ccommd's with every value.
  alignas(kCacheLine) std::atomic<uint64_t> forwarded;  // `latest` value ccommd last sent
  // followed (at the next cache line) by kStateSlots slots of slot_bytes each
};
static_assert(offsetof(StateCell, next_ticket) == kCacheLine, "a reader's part of a cell is one line");

struct alignas(kCacheLine) EventRing {
  std::atomic<uint64_t> head;        // next ticket to claim
  std::atomic<uint64_t> fwd_cursor;  // next ticket ccommd will forward (forwarded signals)
  std::atomic<uint64_t> published;   // events completed (seq_cst, after the slot): ccomm_wait's change counter
  // followed (at the next cache line) by queue_depth slots of slot_bytes each
};

// Four lines, one per writer, so that no per-value counter shares a line with another
// core's: a line another core dirtied costs a transfer (~100 ns) on the next touch, per
// signal, and a 36-signal cycle touches 36 of each. Line 0: the producing application's
// (writes); line 1: ccommd's send side (tx); line 2: what readers read with every value
// (lost, overflow), written rarely; line 3: ccommd's receive side, every value (rx).
struct alignas(kCacheLine) SignalStats {
  std::atomic<uint64_t> writes;       // local writes accepted
  std::atomic<uint64_t> write_errors; // local writes refused (full, busy)
  alignas(kCacheLine) std::atomic<uint64_t> tx;  // values sent by ccommd
  std::atomic<uint64_t> coalesced;    // values replaced by a newer one before ccommd sent them
                                      // (event-driven states when ccommd ran late)
  alignas(kCacheLine) std::atomic<uint64_t> lost;  // gaps in the producer's sequence seen by ccommd
  std::atomic<uint64_t> overflow;     // events a reader lost to ring overrun (all readers)
  std::atomic<uint64_t> stale_transitions;  // fresh -> stale seen by ccommd's supervision
  std::atomic<uint64_t> corrupt;      // copies that failed their check (seqlock.h), by any reader
  std::atomic<uint64_t> fragments_refused;  // large values: fragments refused as bad input
  std::atomic<uint64_t> values_incomplete;  // large values: values given up for a missing fragment
  alignas(kCacheLine) std::atomic<uint64_t> rx;  // values received by ccommd
  std::atomic<uint64_t> last_rx_ns;
};
static_assert(sizeof(SignalStats) == 4 * kCacheLine, "one line per writer (see above)");

struct alignas(kCacheLine) PeerStats {
  std::atomic<uint64_t> frames_rx;
  std::atomic<uint64_t> frames_tx;
  std::atomic<uint64_t> frames_lost;      // gaps in the peer's frame sequence
  std::atomic<uint64_t> frames_reordered; // older than expected (duplicates, reordering)
  std::atomic<uint64_t> heartbeats_rx;
  std::atomic<uint64_t> last_rx_ns;
  std::atomic<uint64_t> down_transitions; // alive -> lost
  std::atomic<uint32_t> alive;            // 1 while heartbeats arrive within peer_timeout_ms
  std::atomic<uint32_t> last_seq;
  std::atomic<uint64_t> last_latency_ns;  // last frame's (arrival - send time); same-clock setups only
  // Its clock as the receive path bounds it from its frames (daemon/clock/peer_clock.h); these
  // fill what was padding, so the size and every offset stay as in layout 6.
  std::atomic<uint64_t> clock_floor_ns;     // int64: min(arrival - send) over the window
  std::atomic<uint64_t> frames_delayed;     // frames held >= 10 ms beyond that floor
  std::atomic<uint64_t> queue_delay_ns;     // the last frame's delay beyond the floor
  std::atomic<uint64_t> queue_delay_max_ns; // the largest so far
  // This node's own entry only: its clock synchronisation (daemon/clock/ptp_state.h).
  std::atomic<uint64_t> clock_state;        // ClockState | PTP port state << 8 | 1 << 16 once published
  std::atomic<uint64_t> clock_offset_ns;    // int64: ptp4l's offset from its master
  std::atomic<uint64_t> clock_path_delay_ns;  // int64: ptp4l's mean path delay (P2P)
};
static_assert(sizeof(PeerStats) == 2 * kCacheLine, "PeerStats keeps layout 6's size");

inline constexpr size_t AlignUp(size_t v, size_t a) { return (v + a - 1) & ~(a - 1); }

template <typename T>
inline T* At(void* base, uint64_t offset) {
  return reinterpret_cast<T*>(static_cast<char*>(base) + offset);
}
template <typename T>
inline const T* At(const void* base, uint64_t offset) {
  return reinterpret_cast<const T*>(static_cast<const char*>(base) + offset);
}

}  // namespace store
}  // namespace ccomm
