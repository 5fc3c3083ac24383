// SPDX-License-Identifier: Apache-2.0
// The system view, the applications' side: ccomm_view_* read the view object
// (store/view.h) that ccommd writes from the node summaries (daemon/engine/system_view_writer.h),
// read-only, through the seqlock of each node record. Names come from the client's
// segment through the public API.
#include <errno.h>

#include <new>

#include "ccomm/ccomm.h"
#include "client/client_internal.h"
#include "client/sized_struct.h"
#include "common/platform.h"
#include "store/view.h"

struct ccomm_view {
  const ccomm_client* client = nullptr;
  ccomm::store::View view;
};

namespace {

namespace st = ccomm::store;
constexpr uint32_t kNoAge = 0xFFFFFFFFu;  // wire::kSummaryNoAge
constexpr uint64_t kNoClockError = 0xFFFFFFFFu;  // wire::kSummaryNoClockError

const char* NodeName(const ccomm_view* v, int node) {
  ccomm_peer_stats ps;
  return ccomm_get_peer_stats(v->client, node, &ps) == 0 ? ps.name : "";
}

// A seqlock reader spins only a few times (store/view.h); a record stays odd for as long
// as ccommd is descheduled mid-rewrite (a time slice, a VM stall), so this monitoring
// API waits it out here, bounded, instead of handing every caller a retry loop.
constexpr int kBusyWaits = 100;
constexpr uint64_t kBusyWaitNs = 500000;  // 100 x 0.5 ms: at most ~50 ms

template <typename Read>
bool ReadPatiently(Read read) {
  for (int i = 0;; ++i) {
    if (read()) return true;
    if (i == kBusyWaits) return false;
    ccomm::platform::SleepNs(kBusyWaitNs);
  }
}

bool Alive(const st::ViewNodeCopy& n, int64_t now) {
  const uint64_t last = n.w[st::kVwLastRxNs];
  return last != 0 && (static_cast<uint64_t>(now) <= last || static_cast<uint64_t>(now) - last <= n.w[st::kVwTimeoutNs]);
}

}  // namespace

extern "C" {

int ccomm_view_open(const ccomm_client* c, ccomm_view** out) {
  if (!c || !out) return CCOMM_E_INVAL;
  *out = nullptr;
  ccomm_view* v = new (std::nothrow) ccomm_view;
  if (!v) return CCOMM_E_SYS;
  v->client = c;
  const int r = v->view.OpenReadOnly(st::View::NameFor(ccomm_node_name(c)));
  const st::ViewHeader* h = r == 0 ? v->view.header() : nullptr;
  if (r != 0 || static_cast<int>(h->node_count) != ccomm_node_count(c) ||
      static_cast<int>(h->signal_count) != ccomm_signal_count(c)) {
    delete v;
    // -EPROTO: another layout version; a view of other dimensions belongs to another
    // configuration than the client's segment (ccommd restarted with a new one).
    return r == -ENOENT ? CCOMM_E_NOENT : r == -EPROTO ? CCOMM_E_VERSION : r ? CCOMM_E_SYS : CCOMM_E_RETIRED;
  }
  *out = v;
  return 0;
}

void ccomm_view_close(ccomm_view* v) { delete v; }

static int FillViewNode(const ccomm_view* v, int node, ccomm_view_node* out) {
  if (!v || node < 0 || node >= static_cast<int>(v->view.header()->node_count)) return CCOMM_E_INVAL;
  st::ViewNodeCopy n;
  if (!ReadPatiently([&] { return v->view.ReadNode(static_cast<uint32_t>(node), &n); })) return CCOMM_E_BUSY;
  const int64_t now = ccomm_now();
  *out = ccomm_view_node();
  out->name = NodeName(v, node);
  out->is_self = static_cast<uint32_t>(node) == v->view.header()->self;
  out->reported = n.w[st::kVwLastRxNs] != 0;
  out->alive = Alive(n, now);
  out->age_ns = out->reported ? now - static_cast<int64_t>(n.w[st::kVwLastRxNs]) : -1;
  if (out->age_ns < -1) out->age_ns = 0;
  out->timeout_ns = static_cast<int64_t>(n.w[st::kVwTimeoutNs]);
  out->uptime_ns = n.w[st::kVwUptimeNs];
  out->peers_alive = n.w[st::kVwPeersAlive];
  out->frames_rx = n.w[st::kVwFramesRx];
  out->frames_tx = n.w[st::kVwFramesTx];
  out->frames_bad = n.w[st::kVwFramesBad];
  out->frames_lost = n.w[st::kVwFramesLost];
  out->socket_drops = n.w[st::kVwSocketDrops];
  out->cycle_ms = static_cast<uint32_t>(n.w[st::kVwCycleMs]);
  out->summaries = n.w[st::kVwSummaries];
  out->clock_state = static_cast<int32_t>(n.w[st::kVwClockState]);
  out->clock_error_ns = n.w[st::kVwClockErrorNs] == kNoClockError ? -1 : static_cast<int64_t>(n.w[st::kVwClockErrorNs]);
  return 0;
}

int ccomm_view_get_node_sized(const ccomm_view* v, int node, ccomm_view_node* out, size_t size) {
  ccomm_view_node n{};
  return ccomm::client::CopySized(FillViewNode(v, node, &n), n, out, size);
}

// The plain symbols (parenthesised: ccomm.h makes the names macros of the *_sized calls).
int(ccomm_view_get_node)(const ccomm_view* v, int node, ccomm_view_node* out) {
  return ccomm_view_get_node_sized(v, node, out, sizeof(ccomm_view_node));
}

// Clock words of a node record, read once without waiting (see ccomm_view_production_age).
struct NodeClock {
  bool current = false;  // a summary of it is there and younger than its timeout
  uint32_t state = 0;
  uint64_t error_ns = kNoClockError;
  int64_t offset_ns = 0;  // its CLOCK_REALTIME - CLOCK_MONOTONIC
};

NodeClock ReadNodeClock(const ccomm_view* v, uint32_t node, int64_t now) {
  NodeClock c;
  st::ViewNodeCopy n;
  if (!v->view.ReadNode(node, &n)) return c;  // being rewritten: no waiting on this path
  c.current = Alive(n, now);
  c.state = static_cast<uint32_t>(n.w[st::kVwClockState]);
  c.error_ns = n.w[st::kVwClockErrorNs];
  c.offset_ns = static_cast<int64_t>(n.w[st::kVwClockOffsetNs]);
  return c;
}

// Reading the two clocks behind an offset (mean of two monotonic readings around the
// realtime one) is exact to well under this.
constexpr int64_t kOffsetReadingNs = 1000;

static int FillProductionAge(const ccomm_view* v, ccomm_signal s, const ccomm_info* info, ccomm_production_age* out) {
  if (!v || !info || s < 0 || s >= static_cast<int>(v->view.header()->signal_count)) return CCOMM_E_INVAL;
  *out = ccomm_production_age{};
  out->age_ns = -1;
  out->error_ns = -1;
  out->production_time_ns = -1;
  ccomm_signal_desc d;
  if (ccomm_describe(v->client, s, &d) != 0) return CCOMM_E_INVAL;
  if (info->seq == 0) {
    out->code = CCOMM_PAGE_NEVER;
    return 0;
  }
  const int64_t now = ccomm::platform::MonotonicNs();
  const int64_t source = static_cast<int64_t>(info->source_time_ns);
  if (d.produced_here) {  // the writer's clock is ours
    out->code = CCOMM_PAGE_SAME_NODE;
    out->known = 1;
    out->age_ns = now > source ? now - source : 0;
    out->error_ns = 0;
    out->production_time_ns = static_cast<int64_t>(ccomm::platform::RealtimeNs()) - out->age_ns;
    return 0;
  }
  const uint32_t producer = ccomm::client::SegmentOf(v->client).dir(static_cast<uint32_t>(s)).producer;
  const NodeClock self = ReadNodeClock(v, v->view.header()->self, now);
  const NodeClock prod = producer < v->view.header()->node_count ? ReadNodeClock(v, producer, now) : NodeClock{};
  if (!self.current || self.state != CCOMM_CLOCK_SYNCED || self.error_ns == kNoClockError) {
    out->code = CCOMM_PAGE_LOCAL_UNSYNCED;
    return 0;
  }
  if (!prod.current) {
    out->code = CCOMM_PAGE_NO_SUMMARY;
    return 0;
  }
  if (prod.state != CCOMM_CLOCK_SYNCED || prod.error_ns == kNoClockError) {
    out->code = CCOMM_PAGE_PRODUCER_UNSYNCED;
    return 0;
  }
  // Both on the common time base: the producer's write in its realtime, ours now.
  const int64_t written = source + prod.offset_ns;
  const int64_t now_common = static_cast<int64_t>(ccomm::platform::RealtimeNs());
  out->code = CCOMM_PAGE_SYNCED;
  out->known = 1;
  out->age_ns = now_common - written;  // may come out below 0 by up to error_ns
  out->production_time_ns = written;
  out->error_ns = static_cast<int64_t>(self.error_ns + prod.error_ns) + 2 * kOffsetReadingNs;
  return 0;
}

static int FillViewSignal(const ccomm_view* v, int node, ccomm_signal s, ccomm_view_signal* out) {
  if (!v || node < 0 || node >= static_cast<int>(v->view.header()->node_count) || s < 0 ||
      s >= static_cast<int>(v->view.header()->signal_count))
    return CCOMM_E_INVAL;
  st::ViewRowCopy r;
  st::ViewNodeCopy n;
  if (!ReadPatiently([&] {
        return v->view.ReadRow(static_cast<uint32_t>(node), static_cast<uint32_t>(s), &r) &&
               v->view.ReadNode(static_cast<uint32_t>(node), &n);
      }))
    return CCOMM_E_BUSY;
  if (!r.present) return CCOMM_E_NOENT;
  const int64_t now = ccomm_now();
  ccomm_signal_desc d;
  *out = ccomm_view_signal();
  out->name = ccomm_describe(v->client, s, &d) == 0 ? d.name : "";
  out->role = r.role;
  out->rate = static_cast<double>(r.rate_mhz) / 1000.0;
  out->lost = r.lost;
  // As the node measured it when it sent the report (node age_ns says how old that is).
  out->age_ns = r.age_ms == kNoAge ? -1 : static_cast<int64_t>(r.age_ms) * 1000000;
  out->stale = (r.flags & 1u) != 0 || !Alive(n, now);  // wire::kRecordStale; or an outdated report
  return 0;
}

int ccomm_view_get_signal_sized(const ccomm_view* v, int node, ccomm_signal s, ccomm_view_signal* out,
                                size_t size) {
  ccomm_view_signal vs{};
  return ccomm::client::CopySized(FillViewSignal(v, node, s, &vs), vs, out, size);
}

int(ccomm_view_get_signal)(const ccomm_view* v, int node, ccomm_signal s, ccomm_view_signal* out) {
  return ccomm_view_get_signal_sized(v, node, s, out, sizeof(ccomm_view_signal));
}

static int FillViewCounters(const ccomm_view* v, ccomm_view_counters* out) {
  if (!v) return CCOMM_E_INVAL;
  const st::ViewHeader* h = v->view.header();
  out->summaries_tx = h->summaries_tx.load(std::memory_order_relaxed);
  out->summaries_rx = h->summaries_rx.load(std::memory_order_relaxed);
  out->summaries_refused = h->summaries_refused.load(std::memory_order_relaxed);
  out->summaries_old = h->summaries_old.load(std::memory_order_relaxed);
  out->summaries_send_errors = h->summaries_send_errors.load(std::memory_order_relaxed);
  out->summary_ms = h->summary_ms;
  return 0;
}

int ccomm_view_get_counters_sized(const ccomm_view* v, ccomm_view_counters* out, size_t size) {
  ccomm_view_counters vc{};
  return ccomm::client::CopySized(FillViewCounters(v, &vc), vc, out, size);
}

int(ccomm_view_get_counters)(const ccomm_view* v, ccomm_view_counters* out) {
  return ccomm_view_get_counters_sized(v, out, sizeof(ccomm_view_counters));
}

}  // extern "C"

extern "C" int ccomm_view_production_age_sized(const ccomm_view* v, ccomm_signal s, const ccomm_info* info,
                                               ccomm_production_age* out, size_t size) {
  ccomm_production_age pa{};
  return ccomm::client::CopySized(FillProductionAge(v, s, info, &pa), pa, out, size);
}
