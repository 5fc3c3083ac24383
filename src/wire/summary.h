// SPDX-License-Identifier: Apache-2.0
// Node summary frames (docs/protocol.md, "Node summary"): a frame with kFlagSummary whose
// payload is one part of the sender's view of itself -- uptime, which peers it hears,
// a few daemon counters, and per signal it produces or consumes: rate, lost, stale, age.
// A view larger than one frame is split into parts that each stand alone.
//
// Like wire.h: caller-provided buffers, no allocation, no access outside them.
#pragma once

#include <cstddef>
#include <cstdint>

#include "wire/wire.h"

namespace ccomm {
namespace wire {

constexpr size_t kSummaryHeadSize = 80;
constexpr size_t kSummaryRecordSize = 24;
/// Records per part, with room for an authentication tag: (1472 - 16 - 32 - 80) / 24.
constexpr size_t kSummaryMaxRecords = 56;
static_assert(kHeaderSize + kSummaryHeadSize + kSummaryMaxRecords * kSummaryRecordSize + kAuthTagSize <= kMaxFrameSize,
              "a full summary part with a tag fits a frame");
constexpr uint32_t kSummaryNoClockError = 0xFFFFFFFFu;  // clock_error_ns: no bound (not synced)
constexpr uint32_t kSummaryNoAge = 0xFFFFFFFFu;  // age_ms of a signal never received/written

enum SummaryRole : uint8_t { kRoleProduced = 1, kRoleConsumed = 2 };
enum SummaryRecordFlags : uint8_t {
  kRecordStale = 1u << 0,  // consumed, has stale_after_ms, and older than that (or never)
  kRecordNever = 1u << 1,  // nothing received (consumed) / written (produced) yet
};

/// The part's fixed head: the sender's node-level view.
struct SummaryHead {
  uint8_t part = 0;           // 0 .. parts-1
  uint8_t parts = 1;          // 1 .. 255
  uint16_t record_count = 0;  // filled by the writer
  uint32_t cycle_ms = 0;      // time the sender takes to send all parts once
  uint64_t uptime_ns = 0;     // since the sender's ccommd started
  uint64_t peers_alive = 0;   // bit i: the sender hears node i (its peer_timeout_ms)
  uint64_t frames_rx = 0, frames_tx = 0, frames_bad = 0;
  uint64_t frames_lost = 0;   // sum over its peers of their frame sequence gaps
  uint64_t socket_drops = 0;
  // The sender's clock (wire v2): its ptp::ClockState (0 none, 1 syncing, 2 synced, 3 lost),
  // a bound on its offset from the grandmaster (kSummaryNoClockError: none), and its
  // CLOCK_REALTIME minus CLOCK_MONOTONIC when it sent the part (maps its source_time_ns,
  // monotonic, to the common time base).
  uint8_t clock_state = 0;
  uint32_t clock_error_ns = kSummaryNoClockError;
  int64_t clock_offset_ns = 0;
};
constexpr uint8_t kSummaryClockStates = 4;  // clock_state values 0..3; others are invalid

struct SummaryRecord {
  uint16_t signal = 0;
  uint8_t role = kRoleProduced;
  uint8_t flags = 0;
  uint32_t rate_mhz = 0;  // values per second x 1000 over the sender's last cycle
  uint64_t lost = 0;      // consumed: the signal's sequence gaps; produced: writes refused
  uint32_t age_ms = kSummaryNoAge;  // since the last value arrived (consumed) / was sent (produced)
};

/// Body rules (DecodeHeader applies them to every kFlagSummary frame): length exactly
/// head + record_count records, record_count <= kSummaryMaxRecords, part < parts,
/// reserved zero, each record's role known, flags known, signals strictly increasing.
bool SummaryBodyValid(const uint8_t* body, size_t len);

/// Reads a frame DecodeHeader accepted with kFlagSummary.
void ReadSummaryHead(const uint8_t* frame, SummaryHead* head);
void ReadSummaryRecord(const uint8_t* frame, uint16_t i, SummaryRecord* r);

/// Builds one summary part in `buf`: Begin, Add per record (increasing signal ids), Finish.
class SummaryWriter {
 public:
  SummaryWriter(uint8_t* buf, size_t cap) : w_(buf, cap) {}
  /// `h.flags` must include kFlagSummary (and kFlagAuth if a tag will follow).
  bool Begin(const FrameHeader& h, const SummaryHead& head);
  /// False if the part is full or the record breaks a body rule.
  bool Add(const SummaryRecord& r);
  /// Frame length without a tag (the tag goes at buf + Finish()), 0 on error.
  size_t Finish();
  uint16_t records() const { return count_; }

 private:
  FrameWriter w_;
  uint8_t* head_ = nullptr;
  uint16_t count_ = 0;
  int32_t last_signal_ = -1;
};

}  // namespace wire
}  // namespace ccomm
