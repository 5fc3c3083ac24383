// SPDX-License-Identifier: Apache-2.0
// The send path behind its writers (send_path.h): a state whose writer was faster than the
// send thread still holds its last kStateSlots values, and a batch step (CCOMM_OPEN_BATCH)
// stores several states one after another. The values in between go out in order, and a
// step's outputs leave whole, whatever the timing of ccommd against the writers.
//
// A state found more than one value ahead of the last one sent is not sent at once: it is
// deferred to the end of the round's loop (DeferCatchUp). There all deferred states are
// cut at one instant that no batch step overlaps (their `latest`, read between two looks
// at steps_active/steps_done), their values since the last one sent copied from the slots
// into a staging area, and only then added to the frames. Read one by one in the loop, a
// state taken before a step landed and one taken after would have their windows of
// kStateSlots values end one step apart: the first still has a step's oldest value that the
// step overwrote in the second (a frame with half a step). A step that lands while the
// staging copies and overwrites a slot before it was read makes the attempt start again
// (bounded); one that overwrote nothing changes nothing (its values follow, below).
//
// Cost: the common round (no state behind, no step landed) pays two loads (SettleSteps).
#include <atomic>

#include "common/platform.h"
#include "daemon/engine/send_path.h"

namespace ccomm {

namespace {

constexpr int kCutAttempts = 4;     // cuts tried while steps keep landing; the last one is sent
constexpr int kSettlePasses = 8;    // rounds of "a step landed: take its values too"
constexpr int kStepSpins = 4096;    // a flush stores a few values: microseconds
constexpr int kStepNaps = 10;       // then ccommd leaves the CPU to a writer preempted in its flush
constexpr uint64_t kStepNapNs = 20000;

size_t StageStride(uint32_t value_bytes) { return (value_bytes + 7u) & ~size_t{7}; }

// Whether a step was storing or landed since steps_done read `steps_at` (with no step
// active then). steps_active first: a step seen ended there has its steps_done raised
// before (EndStep's order), so the second load sees it.
bool StepsMoved(const store::SegmentHeader* h, uint32_t steps_at) {
#ifndef CCOMM_TSAN  // TSan does not model fences (the loads below are acquire loads anyway)
  std::atomic_thread_fence(std::memory_order_acquire);  // after the copies this follows
#endif
  if (h->steps_active.load(std::memory_order_acquire) != 0) return true;
  return h->steps_done.load(std::memory_order_acquire) != steps_at;
}

}  // namespace

// Bounded: waits for batch flushes storing right now. A flush stores a few values: a short
// spin. A writer preempted in its flush on ccommd's own CPU (a one-core board, or ccommd
// above it in priority) finishes only when ccommd leaves the CPU: short sleeps. A writer
// that died in a flush leaves steps_active raised for good: after one wait that timed out,
// ccommd waits again only once it has seen no step active (a round then may send half a
// step of the dead writer, never of a live one that keeps up).
void SendPath::WaitForSteps() {
  const store::SegmentHeader* h = ctx_.segment.header();
  if (h->steps_active.load(std::memory_order_acquire) == 0) {
    steps_wait_ = true;
    return;
  }
  if (!steps_wait_) return;
  for (int spin = 0; spin < kStepSpins; ++spin) {
    platform::CpuRelax();
    if (h->steps_active.load(std::memory_order_acquire) == 0) return;
  }
  for (int nap = 0; nap < kStepNaps; ++nap) {
    platform::SleepNs(kStepNapNs);
    if (h->steps_active.load(std::memory_order_acquire) == 0) return;
  }
  steps_wait_ = false;
}

void SendPath::PrepareCatchUp() {
  const uint32_t n = ctx_.segment.signal_count();
  size_t bytes = 0;
  for (uint32_t id = 0; id < n; ++id) {
    const PreparedSignals::Signal& ps = prepared_[id];
    if (!ps.forwarded || ps.is_event || ps.large || consumers_[id].empty()) continue;
    bytes += store::kStateSlots * StageStride(ctx_.segment.dir(id).value_bytes);
    if (!cfg_->signals[id].period_us) step_states_.push_back(id);
  }
  step_states_.shrink_to_fit();
  deferred_.assign(n, DeferredState());  // a state is deferred at most once per round
  deferred_count_ = 0;
  deferred_mark_.assign(n, 0);
  stage_bytes_.assign(bytes, 0);
  stage_meta_.assign(size_t{n} * store::kStateSlots, store::SlotMeta());
}

void SendPath::DeferCatchUp(uint32_t id) {
  if (deferred_mark_[id]) return;
  deferred_mark_[id] = 1;
  deferred_[deferred_count_++].id = id;
}

// Copies each deferred state's values from the one after the last sent up to its cut,
// those still in its slots, into the staging area. Returns whether a value that should be
// there was not (overwritten, being written, damaged).
bool SendPath::StageDeferred() {
  size_t at = 0;
  uint32_t meta_at = 0;
  bool missed = false;
  for (uint32_t i = 0; i < deferred_count_; ++i) {
    DeferredState& d = deferred_[i];
    const store::StateView& sv = tx_state_[d.id];
    const uint64_t last = tx_signals_[d.id].last_seq;
    const size_t stride = StageStride(sv.value_bytes);
    d.stage_at = at;
    d.meta_at = meta_at;
    d.staged = 0;
    d.gone = 0;
    d.corrupt = 0;
    if (d.cut <= last) continue;  // nothing newer than the last value sent
    // After re-adoption the value before the first one sent is unknown: only the newest.
    const uint64_t first = !last && adopted_                          ? d.cut
                           : d.cut - last - 1 >= store::kStateSlots ? d.cut - (store::kStateSlots - 1)
                                                                    : last + 1;
    d.gone = !last && adopted_ ? 0 : first - last - 1;  // replaced before this thread could take them
    for (uint64_t seq = first; seq <= d.cut; ++seq) {  // bounded: kStateSlots values
      store::SlotMeta& m = stage_meta_[meta_at];
      uint8_t* value = &stage_bytes_[at];
      store::StoreResult r = store::StateReadTicket(sv, seq - 1, value, &m);
      // The newest value by any copy (the inline one, or a ticket numbered otherwise).
      if (seq == d.cut && (r != store::StoreResult::kOk || m.value_seq != seq) && r != store::StoreResult::kCorrupt)
        r = store::StateRead(sv, value, &m);
      if (r == store::StoreResult::kCorrupt) ++d.corrupt;  // damaged in shared memory: never forwarded
      const bool newest = seq == d.cut;
      if (r != store::StoreResult::kOk || (newest ? m.value_seq <= last : m.value_seq != seq)) {
        ++d.gone;
        missed = true;
        continue;
      }
      at += stride;
      ++meta_at;
      ++d.staged;
    }
  }
  return missed;
}

// Adds the staged values to the frames, oldest first, and counts what was gone.
void SendPath::CommitDeferred(uint64_t now) {
  for (uint32_t i = 0; i < deferred_count_; ++i) {
    const DeferredState& d = deferred_[i];
    const store::SignalDirectoryEntry& dir = ctx_.segment.dir(d.id);
    const size_t stride = StageStride(dir.value_bytes);
    uint64_t& last = tx_signals_[d.id].last_seq;
    for (uint32_t k = 0; k < d.staged; ++k) {
      const store::SlotMeta& m = stage_meta_[d.meta_at + k];
      AddEntryCold(d.id, dir, 0, m, &stage_bytes_[d.stage_at + k * stride], now);
      last = m.value_seq;
    }
    if (d.cut > last) last = d.cut;  // a newest value that could not be read is counted gone
    store::SignalStats& st = ctx_.segment.stats(d.id);
    if (d.gone) st.coalesced.fetch_add(d.gone, std::memory_order_relaxed);
    if (d.corrupt) st.corrupt.fetch_add(d.corrupt, std::memory_order_relaxed);
    const store::StateView& sv = tx_state_[d.id];
    if (store::StateForwarded(sv) < d.cut) store::MarkStateForwarded(sv, d.cut);
    deferred_mark_[d.id] = 0;
  }
  deferred_count_ = 0;
}

void SendPath::SendDeferred(uint64_t now) {
  store::SegmentHeader* h = ctx_.segment.header();
  for (int attempt = 0; attempt < kCutAttempts; ++attempt) {
    const bool last_try = attempt + 1 == kCutAttempts;
    WaitForSteps();
    const uint32_t steps_at = h->steps_done.load(std::memory_order_acquire);
    for (uint32_t i = 0; i < deferred_count_; ++i) deferred_[i].cut = store::StateVersion(tx_state_[deferred_[i].id]);
    if (StepsMoved(h, steps_at) && !last_try) continue;  // a step landed between two states' cuts
    const bool missed = StageDeferred();
    if (!missed || !StepsMoved(h, steps_at) || last_try) break;  // else a step overwrote what was to be read
  }
  CommitDeferred(now);
}

// An event-driven state sends every value once. When its writer was faster than this
// thread (ccommd descheduled, a late cycle writing two steps back to back), the values
// between the last one sent and the newest are usually still in the cell's slots
// (kStateSlots copies): they go out first, in order, in the same frame, so a recorder or
// history tap downstream gets every value and nothing is coalesced. Bounded by
// kStateSlots - 1 reads; a value already overwritten counts as coalesced. Used as is for
// values sent in fragments (never part of a step's frame); small states go through
// DeferCatchUp.
uint64_t SendPath::CatchUp(uint32_t id, const store::SignalDirectoryEntry& d, uint64_t last_sent, uint64_t newest,
                           uint64_t now) {
  const store::StateView& sv = tx_state_[id];
  const uint64_t first = newest - last_sent - 1 >= store::kStateSlots ? newest - (store::kStateSlots - 1) : last_sent + 1;
  uint64_t gone = first - last_sent - 1;
  for (uint64_t seq = first; seq < newest; ++seq) {
    store::SlotMeta om;
    const store::StoreResult r = store::StateReadTicket(sv, seq - 1, tx_older_, &om);
    if (r == store::StoreResult::kCorrupt) ctx_.segment.stats(id).corrupt.fetch_add(1, std::memory_order_relaxed);
    if (r != store::StoreResult::kOk || om.value_seq != seq) {
      ++gone;
      continue;
    }
    AddEntryCold(id, d, 0, om, tx_older_, now);
  }
  return gone;
}

// The end of a round's loop: the deferred states go out, and if a batch step landed while
// the round collected, every state a step can write is brought up to date in the frames
// still open (its newer values after the older ones; its dirty bit may not be set yet, and
// one this round took before the step landed is not dirty again until the next round):
// each step's outputs leave together and in order. Bounded: step_states_ once per pass. The
// common case costs two loads.
void SendPath::SettleSteps(uint32_t steps_before, uint64_t now) {
  store::SegmentHeader* h = ctx_.segment.header();
  for (int pass = 0; pass < kSettlePasses; ++pass) {
    WaitForSteps();
    const uint32_t steps_now = h->steps_done.load(std::memory_order_acquire);
    if (steps_now != steps_before) {
      steps_before = steps_now;
      for (const uint32_t id : step_states_) {
        const store::StateView& sv = tx_state_[id];
        if (!deferred_mark_[id] && store::StateVersion(sv) != store::StateForwarded(sv)) DeferCatchUp(id);
      }
    }
    if (deferred_count_ == 0) return;
    SendDeferred(now);
  }
}

}  // namespace ccomm
