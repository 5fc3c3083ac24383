// SPDX-License-Identifier: Apache-2.0
// A peer's clock, bounded from its frames alone (no PTP needed): how long a frame was held
// on its way beyond the path's usual delay, e.g. in this node's socket while its ccommd
// was stopped. docs/design.md ("Time") states the bound; docs/protocol.md the fields used.
//
// Every data frame carries its sender's CLOCK_MONOTONIC send time s; the receiver notes
// its own arrival time a. x = a - s = (our clock - the peer's) + the frame's one-way delay.
// The offset is unknown but changes only by drift, so the smallest x over a recent window
// (NTP's minimum filter) is the offset plus the smallest delay seen, and a frame's
// x - min(x) is how much longer than that fastest frame it travelled: its queueing delay.
// The receive path moves a value's arrival back by that much, so its age counts the time
// it spent queued. Hot path: a few compares, no syscall, no allocation.
#pragma once

#include <atomic>
#include <cstdint>

#include "store/layout.h"

namespace ccomm {

class PeerClock {
 public:
  // The minimum is kept over two buckets of this span (of our clock, counted from a
  // bucket's first frame), so the floor rests on frames at most two spans old: drift
  // (rho, in ppm) moves it by at most rho * 2 * kBucketNs (100 ppm: 0.4 ms). A bucket
  // starts only with a frame, so after a silence the last bucket before it is still
  // there to judge the first frames after it (a queue drained after a stop).
  static constexpr uint64_t kBucketNs = 2'000'000'000;
  // A frame held this much beyond the floor is counted as delayed (frames_delayed):
  // far above a LAN's jitter, far below a stopped process or a full socket queue.
  static constexpr uint64_t kDelayedNs = 10'000'000;

  // One frame of the peer: its send time (the peer's clock) and our arrival time. Returns
  // its estimated queueing delay in ns (0 for the fastest frame of the window).
  uint64_t Observe(uint64_t send_ns, uint64_t arrival_ns) {
    const int64_t x = static_cast<int64_t>(arrival_ns - send_ns);  // offset + delay
    if (!known_) {
      known_ = true;
      current_min_ = previous_min_ = x;
      bucket_start_ns_ = arrival_ns;
      return 0;
    }
    if (arrival_ns - bucket_start_ns_ >= kBucketNs) {
      previous_min_ = current_min_;
      current_min_ = x;
      bucket_start_ns_ = arrival_ns;
    } else if (x < current_min_) {
      current_min_ = x;
    }
    const int64_t floor = floor_ns();
    return x > floor ? static_cast<uint64_t>(x - floor) : 0;
  }

  // The peer's clock restarted (its board rebooted, rule 5's resynchronisation): the
  // floor measured on the old clock means nothing for the new one.
  void Reset() { known_ = false; }

  bool known() const { return known_; }
  // min(arrival - send) over the window: our clock minus the peer's, plus the smallest
  // one-way delay of the window. Meaningful only when known().
  int64_t floor_ns() const { return previous_min_ < current_min_ ? previous_min_ : current_min_; }

 private:
  bool known_ = false;
  int64_t current_min_ = 0;
  int64_t previous_min_ = 0;
  uint64_t bucket_start_ns_ = 0;
};

// A delay to move a value's arrival back by, never back past the clock's start (an
// arrival of 0 would read as "never").
inline uint64_t ClampedQueueDelay(uint64_t delay_ns, uint64_t now_ns) {
  return delay_ns < now_ns ? delay_ns : now_ns - 1;
}

// The peer's clock in its stats (ccomm_get_peer_clock, `ccomm stats`). Receive thread
// only (single writer): plain load/store pairs, no read-modify-write on the hot path.
inline void AccountQueueDelay(store::PeerStats& ps, const PeerClock& clock, uint64_t delay_ns) {
  ps.clock_floor_ns.store(static_cast<uint64_t>(clock.floor_ns()), std::memory_order_relaxed);
  ps.queue_delay_ns.store(delay_ns, std::memory_order_relaxed);
  if (delay_ns > ps.queue_delay_max_ns.load(std::memory_order_relaxed))
    ps.queue_delay_max_ns.store(delay_ns, std::memory_order_relaxed);
  if (delay_ns >= PeerClock::kDelayedNs)
    ps.frames_delayed.store(ps.frames_delayed.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

}  // namespace ccomm
