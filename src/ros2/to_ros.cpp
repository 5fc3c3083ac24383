// SPDX-License-Identifier: Apache-2.0
// ccomm -> ROS 2: wakes on every change of the node's signals (ccomm_wait), reads each
// published signal straight into its preallocated DDS sample and writes it with the
// value's production time as source timestamp (docs/integrations/ros2.md, "Time").
// Nothing is allocated per sample here. A state this node receives is read through the
// history tap when the node has one (<node history="N">): every value is published, not
// only the newest at each wake-up.

#include <cstring>
#include <ctime>
#include <vector>

#include <cstdio>

#include "bridge.h"
#include "common/public/platform_app.h"
#include "sample_layout.h"

namespace ccomm_ros2 {
namespace {

int64_t WallNow() {
  timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);  // vDSO: no syscall
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// Says once per change which time a route's samples carry (not per sample: a stamp kind
// changes when a clock's state does, seconds apart at most).
void NoteStampKind(const Bridge* b, Route* r, int code) {
  if (code == r->stamp_code) return;
  const bool was_known = r->stamp_code == CCOMM_PAGE_SYNCED || r->stamp_code == CCOMM_PAGE_SAME_NODE;
  const bool known = code == CCOMM_PAGE_SYNCED || code == CCOMM_PAGE_SAME_NODE;
  const bool first = r->stamp_code == -2;
  r->stamp_code = code;
  if (!first && was_known == known && !b->opt.verbose) return;
  if (known)
    fprintf(stderr, "ccomm-ros2: %s: source timestamps are production times (%s)\n", r->name.c_str(),
            ccomm_production_age_name(code));
  else
    fprintf(stderr, "ccomm-ros2: %s: source timestamps are local, the arrival here: production time unknown (%s)\n",
            r->name.c_str(), code < 0 ? "no system view" : ccomm_production_age_name(code));
}

// Source timestamp of a value (DDS, like ROS 2, stamps with the wall clock, CLOCK_REALTIME):
// when the value was written on its producer, on the common time base, where that is
// known (both boards' clocks synced, or produced on this board); else, and with
// --stamp arrival, when it reached this node (its local age before now), counted.
dds_time_t SourceTime(Bridge* b, Route* r, const ccomm_info& info) {
  if (b->opt.stamp == StampMode::kWrite) {
    ccomm_production_age pa{};
    int code = -1;
    if (b->to_ros_view && ccomm_view_production_age(b->to_ros_view, r->id, &info, &pa) == 0) code = pa.code;
    NoteStampKind(b, r, code);
    if (code >= 0 && pa.known) {
      r->n.stamped_production.fetch_add(1, std::memory_order_relaxed);
      return pa.production_time_ns;
    }
  }
  r->n.stamped_local.fetch_add(1, std::memory_order_relaxed);
  return WallNow() - (info.age_ns > 0 ? info.age_ns : 0);
}

// Where ccomm_read puts the value: the sample itself (scalars) or its data buffer.
void* ValueOf(Route* r) {
  return r->type->is_array ? static_cast<ArraySample*>(r->sample)->data_.buffer : r->sample;
}

bool Publish(Bridge* b, Route* r, const ccomm_info& info) {
  const dds_time_t ts = SourceTime(b, r, info);
  // A reliable KEEP_ALL (event) writer blocks up to 100 ms while a reader's history is
  // full; retry so no event is dropped for a slow reader that is still there.
  for (int attempt = 0; attempt < 50; ++attempt) {
    dds_return_t rc = dds_write_ts(r->endpoint, r->sample, ts);
    if (rc == DDS_RETCODE_OK) {
      r->n.published.fetch_add(1, std::memory_order_relaxed);
      return true;
    }
    if (rc != DDS_RETCODE_TIMEOUT || b->stop.load(std::memory_order_relaxed)) break;
  }
  r->n.dds_errors.fetch_add(1, std::memory_order_relaxed);
  return false;
}

// Every value of a state the history tap kept since the last call, in order.
int PumpHistory(Bridge* b, ccomm_client* c, Route* r) {
  void* value = ValueOf(r);
  for (int i = 0; i < 100000; ++i) {  // bounded: a writer faster than us cannot pin us here
    ccomm_history_info hi;
    const int st = ccomm_history_read(c, r->id, &r->cursor, value, r->desc.value_bytes, &hi);
    if (st == CCOMM_E_CORRUPT) continue;  // skipped and counted in the cursor's overrun
    if (st < 0) return st;
    const uint64_t overran = hi.overrun > r->last_overrun ? hi.overrun - r->last_overrun : 0;
    if (overran) r->n.skipped.fetch_add(overran, std::memory_order_relaxed);
    r->last_overrun = hi.overrun;
    if (st != CCOMM_FRESH) break;
    // A gap the cursor did not overrun: values that never reached this node.
    const uint64_t gap = r->last_seq != 0 && hi.seq > r->last_seq + 1 ? hi.seq - r->last_seq - 1 : 0;
    if (gap > overran) r->n.lost.fetch_add(gap - overran, std::memory_order_relaxed);
    r->last_seq = hi.seq;
    ccomm_info info{};
    info.status = CCOMM_FRESH;
    info.seq = hi.seq;
    info.source_time_ns = hi.source_time_ns;
    const int64_t now = ccomm_now();
    info.age_ns = now > static_cast<int64_t>(hi.receive_time_ns) ? now - static_cast<int64_t>(hi.receive_time_ns) : 0;
    Publish(b, r, info);
  }
  return 0;
}

// Reads one signal and publishes what is new and fresh. Returns a ccomm error (< 0)
// that needs a reopen, else 0.
int Pump(Bridge* b, ccomm_client* c, Route* r) {
  void* value = ValueOf(r);
  ccomm_info info;
  if (r->history) {
    const int err = PumpHistory(b, c, r);
    if (err < 0) return err;
    // Freshness from the newest value, as below (ROS 2 readers see the DDS deadline).
    const int st = ccomm_read(c, r->id, value, r->desc.value_bytes, &info);
    if (st < 0) return st;
    if (st != CCOMM_FRESH && r->fresh) {
      r->fresh = false;
      r->n.stale.fetch_add(1, std::memory_order_relaxed);
    } else if (st == CCOMM_FRESH) {
      r->fresh = true;
    }
    return 0;
  }
  if (r->desc.is_event) {  // every queued event, in order, once
    for (int i = 0; i < 100000; ++i) {  // bounded: a writer faster than us cannot pin us here
      int st = ccomm_read(c, r->id, value, r->desc.value_bytes, &info);
      if (st < 0) return st;
      if (st == CCOMM_EMPTY || st == CCOMM_NEVER) break;
      if (info.lost > r->last_lost) {
        r->n.lost.fetch_add(info.lost - r->last_lost, std::memory_order_relaxed);
        r->last_lost = info.lost;
      }
      Publish(b, r, info);
    }
    return 0;
  }
  int st = ccomm_read(c, r->id, value, r->desc.value_bytes, &info);
  if (st < 0) return st;
  if (st == CCOMM_FRESH && info.seq != r->last_seq) {
    if (r->last_seq != 0 && info.seq > r->last_seq + 1)
      r->n.skipped.fetch_add(info.seq - r->last_seq - 1, std::memory_order_relaxed);
    r->last_seq = info.seq;
    r->fresh = true;
    Publish(b, r, info);
  } else if (st != CCOMM_FRESH && r->fresh) {
    // Not re-published: the DDS writer's deadline (stale_after_ms) tells ROS 2 readers.
    r->fresh = false;
    r->n.stale.fetch_add(1, std::memory_order_relaxed);
    if (b->opt.verbose) fprintf(stderr, "ccomm-ros2: %s is no longer fresh (%s)\n", r->name.c_str(), ccomm_strerror(st));
  } else if (st == CCOMM_FRESH) {
    r->fresh = true;
  }
  return 0;
}

// A state value already there counts as seen, not new; a received state with a history
// tap is read from the next value on.
void StartRoutes(ccomm_client* c, const std::vector<Route*>& routes) {
  for (Route* r : routes) {
    r->last_seq = r->last_lost = r->last_overrun = 0;
    r->history = !r->desc.is_event && ccomm_history_depth(c, r->id) > 0 &&
                 ccomm_history_start(c, r->id, 0, &r->cursor) == 0;
    ccomm_info info;
    if (!r->desc.is_event && ccomm_read(c, r->id, ValueOf(r), r->desc.value_bytes, &info) >= 0)
      r->last_seq = info.seq;
  }
}

// The system view gives production ages (the node summaries' clocks). Without one (a
// ccommd older than the view) every sample is stamped with its arrival, said once.
void OpenView(Bridge* b, ccomm_client* c, bool quiet = false) {
  b->view_generation = ccomm_daemon_generation(c);
  const int rc = ccomm_view_open(c, &b->to_ros_view);
  if (rc != 0) {
    b->to_ros_view = nullptr;
    if (!quiet)
      fprintf(stderr, "ccomm-ros2: no system view (%s): source timestamps are arrival times\n", ccomm_strerror(rc));
  }
}
void CloseView(Bridge* b) {
  if (b->to_ros_view) ccomm_view_close(b->to_ros_view);
  b->to_ros_view = nullptr;
}
// A ccommd restarted on the same configuration keeps the segment but makes a new view
// (the old one stops: its clocks would time out, every stamp local). It adopts the
// segment (generation + 1) just before it creates the view, so the view is opened again
// when the generation changes and once more 2 s later, in case the first came between.
void FollowView(Bridge* b, ccomm_client* c) {
  const int64_t now = ccomm_now();
  const bool restarted = ccomm_daemon_generation(c) != b->view_generation;
  if (!restarted && (b->view_recheck_ns == 0 || now < b->view_recheck_ns)) return;
  b->view_recheck_ns = restarted ? now + 2000000000 : 0;
  CloseView(b);
  OpenView(b, c, /*quiet=*/restarted);
}

}  // namespace

void RunToRos(Bridge* b) {
  if (b->to_ros.empty()) return;
  if (b->opt.priority > 0) {
    ccomm::platform::RealtimeRequest want;
    want.lock_memory = true;  // no page fault delays the real-time reader (best effort)
    want.fifo_priority = b->opt.priority;
    const int rc = ccomm::platform::SetUpRealtime(want).fifo_priority;
    if (rc != 0)
      fprintf(stderr, "ccomm-ros2: --priority %d: %s (needs CAP_SYS_NICE); running without\n",
              b->opt.priority, strerror(-rc));
  }
  ccomm_client* c = OpenWaiting(b);
  if (!c) return;
  std::vector<uint32_t> offered_ms;  // deadlines offered before a reopen (reserved: no allocation then)
  offered_ms.reserve(b->to_ros.size());
  for (const Route* r : b->to_ros) offered_ms.push_back(r->desc.stale_after_ms);
  bool offered = ResolveRoutes(b, c, b->to_ros);
  for (size_t i = 0; offered && i < b->to_ros.size(); ++i) offered &= OfferCurrentDeadline(b, b->to_ros[i], offered_ms[i]);
  if (!offered) { b->fatal = 1; b->stop = true; ccomm_close(c); return; }
  StartRoutes(c, b->to_ros);
  OpenView(b, c);
  while (!b->stop.load(std::memory_order_relaxed)) {
    ccomm_wait(c, 100);  // returns at once on a change; 100 ms to notice stop/retirement
    FollowView(b, c);
    int err = 0;
    for (Route* r : b->to_ros) {
      err = Pump(b, c, r);
      if (err < 0) break;
    }
    if (err == CCOMM_E_RETIRED || err == CCOMM_E_VERSION) {
      // ccommd replaced the segment (restart with a new configuration): attach anew.
      if (b->opt.verbose) fprintf(stderr, "ccomm-ros2: segment retired, reopening\n");
      CloseView(b);
      ccomm_close(c);
      c = OpenWaiting(b);
      if (!c) return;
      offered_ms.clear();
      for (const Route* r : b->to_ros) offered_ms.push_back(r->desc.stale_after_ms);
      if (!ResolveRoutes(b, c, b->to_ros)) { b->fatal = 1; b->stop = true; break; }
      // A new configuration may change a deadline: offer the one it says (re-read here).
      offered = true;
      for (size_t i = 0; i < b->to_ros.size(); ++i) offered &= OfferCurrentDeadline(b, b->to_ros[i], offered_ms[i]);
      if (!offered) { b->fatal = 1; b->stop = true; break; }
      b->reopens.fetch_add(1, std::memory_order_relaxed);
      StartRoutes(c, b->to_ros);  // a new segment counts anew
      OpenView(b, c);
    } else if (err < 0) {
      fprintf(stderr, "ccomm-ros2: reading signals: %s\n", ccomm_strerror(err));
      b->fatal = 1;
      b->stop = true;
    }
  }
  CloseView(b);
  if (c) ccomm_close(c);
}

}  // namespace ccomm_ros2
