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
//
// A floor set by one frame must be borne out: a frame with a stamp from the future (forged,
// without a key; or a board whose clock jumped) gives a tiny x and would make every genuine
// frame after it look queued for as long as the stamp is ahead, until the window turns over.
// So a floor that a frame set (the first one, or one lowering it by more than kConfirmNs)
// is confirmed by a later frame within kConfirmNs of it; if frames keep coming for one
// heartbeat interval and none does, the floor is re-based on the lowest of them. A forged
// stamp thus holds the floor down for one heartbeat interval at most.
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
  // A frame within this of the floor confirms it; one lowering it by more must be confirmed
  // (far above a LAN's jitter, so genuine frames confirm a genuine floor at once).
  static constexpr int64_t kConfirmNs = 1'000'000;

  // How long an unconfirmed floor stands: the peers' heartbeat interval (<network
  // heartbeat_ms>), within which a live peer sends at least one frame.
  void set_confirm_window_ns(uint64_t ns) { confirm_window_ns_ = ns; }

  // One frame of the peer: its send time (the peer's clock) and our arrival time. Returns
  // its estimated queueing delay in ns (0 for the fastest frame of the window).
  uint64_t Observe(uint64_t send_ns, uint64_t arrival_ns) {
    const int64_t x = static_cast<int64_t>(arrival_ns - send_ns);  // offset + delay
    if (!known_) {
      known_ = true;
      current_min_ = previous_min_ = x;
      bucket_start_ns_ = arrival_ns;
      Unconfirmed(arrival_ns);
      return 0;
    }
    if (unconfirmed_) {
      if (x <= floor_ns() + kConfirmNs) {
        unconfirmed_ = false;  // a second frame at that level: the floor is real
      } else {
        if (x < since_min_) since_min_ = x;
        if (arrival_ns - unconfirmed_since_ns_ > confirm_window_ns_) {
          // A heartbeat interval of frames, none near the floor: it rested on a stamp from
          // the future. Re-based on what the frames since then show.
          current_min_ = previous_min_ = since_min_;
          bucket_start_ns_ = arrival_ns;
          unconfirmed_ = false;
        }
      }
    }
    const int64_t before = floor_ns();
    if (arrival_ns - bucket_start_ns_ >= kBucketNs) {
      previous_min_ = current_min_;
      current_min_ = x;
      bucket_start_ns_ = arrival_ns;
    } else if (x < current_min_) {
      current_min_ = x;
    }
    if (x < before - kConfirmNs) Unconfirmed(arrival_ns);  // this frame alone lowered the floor
    const int64_t floor = floor_ns();
    return x > floor ? static_cast<uint64_t>(x - floor) : 0;
  }

  // The peer's clock restarted (its board rebooted, rule 5's resynchronisation): the
  // floor measured on the old clock means nothing for the new one.
  void Reset() {
    known_ = false;
    unconfirmed_ = false;
  }

  bool known() const { return known_; }
  // min(arrival - send) over the window: our clock minus the peer's, plus the smallest
  // one-way delay of the window. Meaningful only when known().
  int64_t floor_ns() const { return previous_min_ < current_min_ ? previous_min_ : current_min_; }

 private:
  void Unconfirmed(uint64_t arrival_ns) {
    unconfirmed_ = true;
    unconfirmed_since_ns_ = arrival_ns;
    since_min_ = INT64_MAX;
  }

  bool known_ = false;
  bool unconfirmed_ = false;         // the floor rests on one frame (see above)
  uint64_t unconfirmed_since_ns_ = 0;  // that frame's arrival
  int64_t since_min_ = 0;            // the smallest x of the frames after it
  uint64_t confirm_window_ns_ = 100'000'000;
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
