// SPDX-License-Identifier: Apache-2.0
// Node summary codec (layout in docs/protocol.md, "Node summary"). Same conventions as
// wire.cpp: memcpy plus explicit byte swaps, every access bounds-checked first.
#include "wire/summary.h"

#include <cstring>

namespace ccomm {
namespace wire {
namespace {

// Big-endian field access: one definition, wire.h's.
using be::Load;
using be::Store;

// Head offsets (from the start of the payload).
constexpr size_t kOffPart = 0, kOffParts = 1, kOffRecords = 2, kOffCycle = 4, kOffUptime = 8,
                 kOffPeers = 16, kOffRx = 24, kOffTx = 32, kOffBad = 40, kOffLost = 48, kOffDrops = 56,
                 kOffClockState = 64, kOffClockReserved = 65, kOffClockError = 68, kOffClockOffset = 72;
// Record offsets.
constexpr size_t kROffSignal = 0, kROffRole = 2, kROffFlags = 3, kROffRate = 4, kROffLost = 8,
                 kROffAge = 16, kROffReserved = 20;
constexpr uint8_t kKnownRecordFlags = kRecordStale | kRecordNever;

inline bool RoleKnown(uint8_t role) { return role == kRoleProduced || role == kRoleConsumed; }

}  // namespace

bool SummaryBodyValid(const uint8_t* body, size_t len) {
  if (body == nullptr || len < kSummaryHeadSize) return false;
  const uint8_t part = body[kOffPart], parts = body[kOffParts];
  const uint16_t n = Load<uint16_t>(body + kOffRecords);
  if (parts == 0 || part >= parts || n > kSummaryMaxRecords) return false;
  if (body[kOffClockState] >= kSummaryClockStates || body[kOffClockReserved] != 0 || body[kOffClockReserved + 1] != 0 ||
      body[kOffClockReserved + 2] != 0)
    return false;
  if (len != kSummaryHeadSize + size_t{n} * kSummaryRecordSize) return false;
  int32_t last = -1;
  for (uint16_t i = 0; i < n; ++i) {
    const uint8_t* r = body + kSummaryHeadSize + size_t{i} * kSummaryRecordSize;
    const int32_t sig = Load<uint16_t>(r + kROffSignal);
    if (sig <= last || !RoleKnown(r[kROffRole]) || (r[kROffFlags] & ~kKnownRecordFlags) != 0 ||
        Load<uint32_t>(r + kROffReserved) != 0)
      return false;
    last = sig;
  }
  return true;
}

void ReadSummaryHead(const uint8_t* frame, SummaryHead* h) {
  const uint8_t* b = frame + kHeaderSize;
  h->part = b[kOffPart];
  h->parts = b[kOffParts];
  h->record_count = Load<uint16_t>(b + kOffRecords);
  h->cycle_ms = Load<uint32_t>(b + kOffCycle);
  h->uptime_ns = Load<uint64_t>(b + kOffUptime);
  h->peers_alive = Load<uint64_t>(b + kOffPeers);
  h->frames_rx = Load<uint64_t>(b + kOffRx);
  h->frames_tx = Load<uint64_t>(b + kOffTx);
  h->frames_bad = Load<uint64_t>(b + kOffBad);
  h->frames_lost = Load<uint64_t>(b + kOffLost);
  h->socket_drops = Load<uint64_t>(b + kOffDrops);
  h->clock_state = b[kOffClockState];
  h->clock_error_ns = Load<uint32_t>(b + kOffClockError);
  h->clock_offset_ns = static_cast<int64_t>(Load<uint64_t>(b + kOffClockOffset));
}

void ReadSummaryRecord(const uint8_t* frame, uint16_t i, SummaryRecord* r) {
  const uint8_t* p = frame + kHeaderSize + kSummaryHeadSize + size_t{i} * kSummaryRecordSize;
  r->signal = Load<uint16_t>(p + kROffSignal);
  r->role = p[kROffRole];
  r->flags = p[kROffFlags];
  r->rate_mhz = Load<uint32_t>(p + kROffRate);
  r->lost = Load<uint64_t>(p + kROffLost);
  r->age_ms = Load<uint32_t>(p + kROffAge);
}

bool SummaryWriter::Begin(const FrameHeader& h, const SummaryHead& head) {
  count_ = 0;
  last_signal_ = -1;
  head_ = nullptr;
  if (!(h.flags & kFlagSummary) || head.parts == 0 || head.part >= head.parts ||
      head.clock_state >= kSummaryClockStates)
    return false;
  w_.Begin(h);
  head_ = w_.ReserveBody(kSummaryHeadSize);
  if (head_ == nullptr) return false;
  head_[kOffPart] = head.part;
  head_[kOffParts] = head.parts;
  Store<uint16_t>(head_ + kOffRecords, 0);
  Store<uint32_t>(head_ + kOffCycle, head.cycle_ms);
  Store<uint64_t>(head_ + kOffUptime, head.uptime_ns);
  Store<uint64_t>(head_ + kOffPeers, head.peers_alive);
  Store<uint64_t>(head_ + kOffRx, head.frames_rx);
  Store<uint64_t>(head_ + kOffTx, head.frames_tx);
  Store<uint64_t>(head_ + kOffBad, head.frames_bad);
  Store<uint64_t>(head_ + kOffLost, head.frames_lost);
  Store<uint64_t>(head_ + kOffDrops, head.socket_drops);
  head_[kOffClockState] = head.clock_state;
  head_[kOffClockReserved] = head_[kOffClockReserved + 1] = head_[kOffClockReserved + 2] = 0;
  Store<uint32_t>(head_ + kOffClockError, head.clock_error_ns);
  Store<uint64_t>(head_ + kOffClockOffset, static_cast<uint64_t>(head.clock_offset_ns));
  return true;
}

bool SummaryWriter::Add(const SummaryRecord& r) {
  if (head_ == nullptr || count_ >= kSummaryMaxRecords) return false;
  if (int32_t{r.signal} <= last_signal_ || !RoleKnown(r.role) || (r.flags & ~kKnownRecordFlags) != 0) return false;
  uint8_t* p = w_.ReserveBody(kSummaryRecordSize);
  if (p == nullptr) return false;
  Store<uint16_t>(p + kROffSignal, r.signal);
  p[kROffRole] = r.role;
  p[kROffFlags] = r.flags;
  Store<uint32_t>(p + kROffRate, r.rate_mhz);
  Store<uint64_t>(p + kROffLost, r.lost);
  Store<uint32_t>(p + kROffAge, r.age_ms);
  Store<uint32_t>(p + kROffReserved, 0);
  ++count_;
  last_signal_ = r.signal;
  Store<uint16_t>(head_ + kOffRecords, count_);
  return true;
}

size_t SummaryWriter::Finish() { return head_ ? w_.Finish() : 0; }

}  // namespace wire
}  // namespace ccomm
