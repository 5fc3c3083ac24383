// SPDX-License-Identifier: Apache-2.0
// Reassembler state machine (states and invariants in fragment.h).
#include "wire/fragment.h"

#include "common/value_type.h"

namespace ccomm {
namespace wire {
namespace {

// A part this far (or less) behind the value in progress is a late or duplicated one
// and refused; further back, the producer restarted its numbering (as rule 6's resync
// distance in docs/protocol.md), and the part may start a value.
constexpr int32_t kStaleDistance = 1024;

}  // namespace

const char* FragmentResultName(FragmentResult r) {
  switch (r) {
    case FragmentResult::kPending: return "pending";
    case FragmentResult::kComplete: return "complete";
    case FragmentResult::kLostValue: return "lost_value";
    case FragmentResult::kGap: return "gap";
    case FragmentResult::kDuplicate: return "duplicate";
    case FragmentResult::kOverlap: return "overlap";
    case FragmentResult::kStale: return "stale";
    case FragmentResult::kInconsistent: return "inconsistent";
    case FragmentResult::kOversized: return "oversized";
    case FragmentResult::kNotFragment: return "not_fragment";
  }
  return "unknown";
}

FragmentResult Reassembler::Start(const EntryView& e, uint32_t* abandoned) {
  seq_ = e.seq;
  if (e.offset != 0) {  // its first part(s) never came: the value is lost
    ++*abandoned;
    state_ = State::kDiscarding;
    return FragmentResult::kGap;
  }
  state_ = State::kAssembling;
  type_ = e.type;
  flags_ = e.flags;
  count_ = e.count;
  time_ = e.source_time_ns;
  ValueToHost(e.type, e.value, buf_, e.value_len / ValueTypeSize(e.type));
  next_ = e.value_len;  // < total: DecodeHeader accepts only strict parts
  return FragmentResult::kPending;
}

FragmentResult Reassembler::Accept(const EntryView& e, uint32_t* abandoned) {
  *abandoned = 0;
  if (!(e.flags & kEntryFragment)) return FragmentResult::kNotFragment;
  // DecodeHeader guarantees offset + value_len <= total_len, element alignment and a
  // known type; the total must also be exactly this signal's size, so the copy below
  // stays inside buf_.
  if (e.total_len != cap_ || buf_ == nullptr) return FragmentResult::kOversized;

  if (state_ == State::kIdle) {
    if (have_last_) {
      const int32_t d = static_cast<int32_t>(e.seq - last_seq_);
      if (d == 0) return resent_ && e.offset == 0 ? Start(e, abandoned) : FragmentResult::kDuplicate;
      if (d < 0 && d >= -kStaleDistance) return FragmentResult::kStale;
    }
    return Start(e, abandoned);
  }

  const int32_t d = static_cast<int32_t>(e.seq - seq_);
  if (d < 0 && d >= -kStaleDistance) return FragmentResult::kStale;
  if (d != 0) {  // a newer value (or a restarted producer's): the one in progress is over
    if (state_ == State::kAssembling) ++*abandoned;
    return Start(e, abandoned);
  }
  // A periodic re-send of the same value starts over (the bytes are the same; an
  // assembly in progress is not lost, it continues from the new first part).
  if (resent_ && e.offset == 0) return Start(e, abandoned);
  if (state_ == State::kDiscarding) return FragmentResult::kLostValue;

  // Same value, in progress.
  if (e.type != type_ || e.count != count_ || e.flags != flags_ || e.source_time_ns != time_)
    return FragmentResult::kInconsistent;
  if (e.offset < next_)
    return e.offset + e.value_len <= next_ ? FragmentResult::kDuplicate : FragmentResult::kOverlap;
  if (e.offset > next_) {  // a part is missing: parts travel in order, so it is lost
    ++*abandoned;
    state_ = State::kDiscarding;
    return FragmentResult::kGap;
  }
  ValueToHost(e.type, e.value, buf_ + next_, e.value_len / ValueTypeSize(e.type));
  next_ += e.value_len;
  if (next_ < cap_) return FragmentResult::kPending;
  state_ = State::kIdle;
  have_last_ = true;
  last_seq_ = seq_;
  return FragmentResult::kComplete;
}

}  // namespace wire
}  // namespace ccomm
