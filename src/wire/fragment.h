// SPDX-License-Identifier: Apache-2.0
// Reassembly of large values (docs/protocol.md, "Large values"): a value too large for one
// frame travels as fragment entries, in order, each in its own frame. A Reassembler (one
// per large signal a node consumes) collects the parts of one value at a time into a
// caller-provided buffer and reports the value only once every byte of it has arrived, so
// what is stored is always one whole value, never a mix of two.
//
// Refused (counted by the caller from the result, the value in progress unchanged):
// duplicates, overlapping parts, parts of an older value, parts that disagree with the
// value in progress, totals larger than the buffer. A gap (a part missing or out of
// order) abandons the value: it is never reported, and its sequence number is missing
// from the stream the receiver sees, which rule 6 counts as one lost value.
//
// No allocation, no system call: safe on the receive thread.
#pragma once

#include <cstddef>
#include <cstdint>

#include "wire/wire.h"

namespace ccomm {
namespace wire {

enum class FragmentResult : uint8_t {
  kPending = 0,    // accepted, value still incomplete
  kComplete,       // accepted, and the value is whole: value() holds it until the next Accept
  kLostValue,      // a part of a value already abandoned: ignored (the value is lost anyway)
  kGap,            // a part beyond what arrived: the value is abandoned (lost)
  // Refusals (bad or stray input): nothing changes.
  kDuplicate,      // a part already received
  kOverlap,        // a part that overlaps received bytes and new ones
  kStale,          // a part of an older value than the one in progress / last completed
  kInconsistent,   // type, count, kind or source time differ from the value in progress
  kOversized,      // total length above the buffer (or not the signal's configured size)
  kNotFragment,    // the entry is not a fragment entry
};
const char* FragmentResultName(FragmentResult r);
inline bool IsRefusal(FragmentResult r) { return r >= FragmentResult::kDuplicate; }

class Reassembler {
 public:
  /// `buf` holds exactly `value_bytes` bytes (the signal's configured value size) and
  /// receives the value in host byte order. `resent`: the producer sends the same value
  /// again (a periodic signal), so a first part of the value in progress or last
  /// completed starts its assembly again instead of being refused as a duplicate (the
  /// bytes are the same: one seq is one value).
  void Init(uint8_t* buf, uint32_t value_bytes, bool resent = false) {
    buf_ = buf;
    cap_ = value_bytes;
    resent_ = resent;
    Reset();
  }
  /// Forgets everything (the producer restarted: its sequence numbers start over).
  void Reset() {
    state_ = State::kIdle;
    have_last_ = false;
  }
  /// Takes one fragment entry (already validated by DecodeHeader). `*abandoned` is set to
  /// the number of values (0, 1 or 2) given up because of this part: the one in progress
  /// (a newer value began, or this part shows a gap) and this part's own value if its
  /// first part is missing. Each value that is never completed is counted once.
  FragmentResult Accept(const EntryView& e, uint32_t* abandoned);

  const uint8_t* value() const { return buf_; }
  uint32_t seq() const { return seq_; }
  uint64_t source_time_ns() const { return time_; }
  bool assembling() const { return state_ == State::kAssembling; }

 private:
  // kIdle: no value in progress; if have_last_, last_seq_ is the last value completed or
  //   abandoned (its late parts are refused as duplicates / stale).
  // kAssembling: bytes [0, next_) of buf_ hold the first parts of value seq_, in host
  //   order; 0 < next_ < cap_; type_, count_, flags_, time_ are that value's.
  // kDiscarding: value seq_ lost a part; its remaining parts are ignored.
  enum class State : uint8_t { kIdle, kAssembling, kDiscarding };
  FragmentResult Start(const EntryView& e, uint32_t* abandoned);

  uint8_t* buf_ = nullptr;
  uint32_t cap_ = 0;
  bool resent_ = false;
  State state_ = State::kIdle;
  uint32_t seq_ = 0;
  uint32_t next_ = 0;
  uint8_t type_ = 0, flags_ = 0;
  uint16_t count_ = 0;
  uint64_t time_ = 0;
  bool have_last_ = false;
  uint32_t last_seq_ = 0;
};

}  // namespace wire
}  // namespace ccomm
