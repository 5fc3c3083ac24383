// SPDX-License-Identifier: Apache-2.0
// libccomm's introspection calls (ccomm.h): error texts, signal descriptions, statistics
// and the daemon's state. None is on a control loop's path; all read the segment through
// the handle's public view of it (client_internal.h), like history.cpp.
#include <stdint.h>
#include <string.h>

#include "ccomm/ccomm.h"
#include "common/value_text.h"
#include "client/client_internal.h"
#include "client/sized_struct.h"
#include "common/platform.h"
#include "common/value_type.h"
#include "store/freshness.h"
#include "store/segment.h"

namespace {

namespace st = ccomm::store;
namespace platform = ccomm::platform;
using ccomm::client::CopySized;
using ccomm::client::SegmentOf;

// ccomm_signal_stats as ccomm 0.1.0 laid it out: what the plain ccomm_get_signal_stats
// symbol fills for programs built against that header.
struct SignalStats010 {
  uint64_t writes, write_errors, tx, coalesced, rx, lost, overflow, stale_transitions;
  int64_t last_rx_age_ns;
  int32_t stale;
};
static_assert(sizeof(SignalStats010) == 80, "the ccomm 0.1.0 layout");

bool ValidSignal(const ccomm_client* c, ccomm_signal s) {
  return c && s >= 0 && static_cast<uint32_t>(s) < SegmentOf(c).signal_count();
}

// Age of a value stored at `stored_ns` as seen at `now` (0 if it arrived after `now`).
int64_t Age(uint64_t now, uint64_t stored_ns) { return now > stored_ns ? static_cast<int64_t>(now - stored_ns) : 0; }

}  // namespace

extern "C" {

const char* ccomm_strerror(int code) {
  switch (code) {
    case CCOMM_FRESH: return "fresh";
    case CCOMM_STALE: return "stale";
    case CCOMM_NEVER: return "never received";
    case CCOMM_EMPTY: return "no new event";
    case CCOMM_E_INVAL: return "invalid argument";
    case CCOMM_E_NOENT: return "no such signal or segment (is ccommd running for this node?)";
    case CCOMM_E_TYPE: return "type or length does not match the signal";
    case CCOMM_E_PERM: return "this node is not the signal's producer";
    case CCOMM_E_FULL: return "event queue full (ccommd is not forwarding)";
    case CCOMM_E_BUSY: return "concurrent writers took every slot; retry";
    case CCOMM_E_SYS: return "operating system error (see errno)";
    case CCOMM_E_VERSION: return "shared-memory layout version differs from this library";
    case CCOMM_E_RETIRED: return "segment replaced by a new configuration; reopen";
    case CCOMM_E_CORRUPT: return "value in shared memory failed its check (segment written over); not returned";
    default: return "unknown code";
  }
}

static int FillDescription(const ccomm_client* c, ccomm_signal s, ccomm_signal_desc* out) {
  if (!ValidSignal(c, s)) return CCOMM_E_INVAL;
  const st::Segment& seg = SegmentOf(c);
  const st::SignalDirectoryEntry& d = seg.dir(static_cast<uint32_t>(s));
  out->name = d.name;
  out->type = d.type;
  out->count = d.count;
  out->value_bytes = d.value_bytes;
  out->is_event = (d.flags & st::kSigEvent) ? 1 : 0;
  out->produced_here = (d.flags & st::kSigProducedHere) ? 1 : 0;
  out->consumed_here = (d.flags & st::kSigConsumedHere) ? 1 : 0;
  out->forwarded = (d.flags & st::kSigForwarded) ? 1 : 0;
  out->stale_after_ms = d.stale_after_ms;
  out->producer = d.producer < seg.node_count() ? seg.node_name(d.producer) : "";
  return 0;
}

int ccomm_describe_sized(const ccomm_client* c, ccomm_signal s, ccomm_signal_desc* out, size_t size) {
  ccomm_signal_desc d{};
  return CopySized(FillDescription(c, s, &d), d, out, size);
}

// The plain symbols (parenthesised: ccomm.h makes the names macros of the *_sized calls).
int(ccomm_describe)(const ccomm_client* c, ccomm_signal s, ccomm_signal_desc* out) {
  // the layout programs built before `forwarded` was appended pass
  return ccomm_describe_sized(c, s, out, ccomm::client::FirstSize<ccomm_signal_desc>::value);
}

int ccomm_parse_element(int32_t type, const char* text, void* out) {
  if (!text || !out || !ccomm_type_name(type)) return CCOMM_E_INVAL;
  using ccomm::value_text::NumResult;
  const NumResult r = ccomm::value_text::ParseValueElement(static_cast<ccomm::ValueType>(type), text, out);
  return r == NumResult::kOk ? 0 : r == NumResult::kRange ? CCOMM_E_TYPE : CCOMM_E_INVAL;
}

const char* ccomm_type_name(int32_t type) {
  return type > 0 && ccomm::ValueTypeSize(static_cast<uint8_t>(type)) ? ccomm::ValueTypeName(static_cast<ccomm::ValueType>(type))
                                                                      : nullptr;
}

uint32_t ccomm_type_size(int32_t type) {
  return type > 0 && type < 256 ? static_cast<uint32_t>(ccomm::ValueTypeSize(static_cast<uint8_t>(type))) : 0;
}

int ccomm_type_from_name(const char* name) {
  if (!name) return CCOMM_E_INVAL;
  for (ccomm::ValueType t : ccomm::kAllValueTypes)
    if (strcmp(ccomm::ValueTypeName(t), name) == 0) return static_cast<int>(t);
  return CCOMM_E_INVAL;
}

int ccomm_daemon_alive(const ccomm_client* c) {
  if (!c) return 0;
  const st::SegmentHeader* h = SegmentOf(c).header();
  if (h->daemon_pid.load(std::memory_order_acquire) == 0) return 0;
  uint64_t hb = h->daemon_heartbeat_ns.load(std::memory_order_acquire);
  return platform::MonotonicNs() - hb < 1000000000ull ? 1 : 0;
}

static int FillSignalStats(const ccomm_client* c, ccomm_signal s, ccomm_signal_stats* out) {
  if (!ValidSignal(c, s)) return CCOMM_E_INVAL;
  const st::Segment& seg = SegmentOf(c);
  const st::SignalDirectoryEntry& d = seg.dir(static_cast<uint32_t>(s));
  const st::SignalStats& ss = seg.stats(static_cast<uint32_t>(s));
  const uint64_t stale_ns = uint64_t{d.stale_after_ms} * 1000000;
  out->writes = ss.writes.load(std::memory_order_relaxed);
  out->write_errors = ss.write_errors.load(std::memory_order_relaxed);
  out->tx = ss.tx.load(std::memory_order_relaxed);
  out->coalesced = ss.coalesced.load(std::memory_order_relaxed);
  out->rx = ss.rx.load(std::memory_order_relaxed);
  out->lost = ss.lost.load(std::memory_order_relaxed);
  out->overflow = ss.overflow.load(std::memory_order_relaxed);
  out->stale_transitions = ss.stale_transitions.load(std::memory_order_relaxed);
  out->corrupt = ss.corrupt.load(std::memory_order_relaxed);
  out->fragments_refused = ss.fragments_refused.load(std::memory_order_relaxed);
  out->values_incomplete = ss.values_incomplete.load(std::memory_order_relaxed);
  const uint64_t last = ss.last_rx_ns.load(std::memory_order_relaxed);
  const uint64_t now = platform::MonotonicNs();
  out->last_rx_age_ns = last ? Age(now, last) : -1;
  out->stale = (d.flags & st::kSigConsumedHere) &&
               st::IsStale(last != 0, last ? static_cast<uint64_t>(Age(now, last)) : 0, stale_ns);
  return 0;
}

int ccomm_node_count(const ccomm_client* c) { return c ? static_cast<int>(SegmentOf(c).node_count()) : CCOMM_E_INVAL; }

int ccomm_get_signal_stats_sized(const ccomm_client* c, ccomm_signal s, ccomm_signal_stats* out, size_t size) {
  ccomm_signal_stats st{};
  return CopySized(FillSignalStats(c, s, &st), st, out, size);
}

int(ccomm_get_signal_stats)(const ccomm_client* c, ccomm_signal s, ccomm_signal_stats* out) {
  if (!out) return CCOMM_E_INVAL;
  ccomm_signal_stats st{};
  const int rc = FillSignalStats(c, s, &st);
  if (rc != 0) return rc;
  SignalStats010 old{st.writes, st.write_errors, st.tx,   st.coalesced,         st.rx,
                     st.lost,   st.overflow,     st.stale_transitions, st.last_rx_age_ns, st.stale};
  memcpy(static_cast<void*>(out), &old, sizeof old);
  return 0;
}

static int FillPeerStats(const ccomm_client* c, int node, ccomm_peer_stats* out) {
  if (!c || node < 0 || static_cast<uint32_t>(node) >= SegmentOf(c).node_count()) return CCOMM_E_INVAL;
  const st::Segment& seg = SegmentOf(c);
  const uint32_t n = static_cast<uint32_t>(node);
  const st::PeerStats& ps = seg.peer(n);
  out->name = seg.node_name(n);
  out->is_self = n == seg.node_id();
  out->alive = ps.alive.load(std::memory_order_relaxed) ? 1 : 0;
  out->frames_rx = ps.frames_rx.load(std::memory_order_relaxed);
  out->frames_tx = ps.frames_tx.load(std::memory_order_relaxed);
  out->frames_lost = ps.frames_lost.load(std::memory_order_relaxed);
  out->frames_reordered = ps.frames_reordered.load(std::memory_order_relaxed);
  out->heartbeats_rx = ps.heartbeats_rx.load(std::memory_order_relaxed);
  out->down_transitions = ps.down_transitions.load(std::memory_order_relaxed);
  const uint64_t last = ps.last_rx_ns.load(std::memory_order_relaxed);
  out->last_rx_age_ns = last ? Age(platform::MonotonicNs(), last) : -1;
  return 0;
}

int ccomm_get_peer_stats_sized(const ccomm_client* c, int node, ccomm_peer_stats* out, size_t size) {
  ccomm_peer_stats ps{};
  return CopySized(FillPeerStats(c, node, &ps), ps, out, size);
}

int(ccomm_get_peer_stats)(const ccomm_client* c, int node, ccomm_peer_stats* out) {
  return ccomm_get_peer_stats_sized(c, node, out, sizeof(ccomm_peer_stats));
}

static int FillPeerClock(const ccomm_client* c, int node, ccomm_peer_clock* out) {
  if (!c || !out || node < 0 || static_cast<uint32_t>(node) >= SegmentOf(c).node_count()) return CCOMM_E_INVAL;
  const st::PeerStats& ps = SegmentOf(c).peer(static_cast<uint32_t>(node));
  *out = ccomm_peer_clock{};
  // Known once a frame of it was received (the receive path stores the floor with it).
  out->known = ps.frames_rx.load(std::memory_order_acquire) > 0 ? 1 : 0;
  out->offset_floor_ns = static_cast<int64_t>(ps.clock_floor_ns.load(std::memory_order_relaxed));
  out->queue_delay_ns = ps.queue_delay_ns.load(std::memory_order_relaxed);
  out->queue_delay_max_ns = ps.queue_delay_max_ns.load(std::memory_order_relaxed);
  out->frames_delayed = ps.frames_delayed.load(std::memory_order_relaxed);
  return 0;
}

static int FillClockState(const ccomm_client* c, ccomm_clock_state* out) {
  if (!c || !out) return CCOMM_E_INVAL;
  const st::Segment& seg = SegmentOf(c);
  const st::PeerStats& self = seg.peer(seg.node_id());
  *out = ccomm_clock_state{};
  const uint64_t word = self.clock_state.load(std::memory_order_acquire);
  out->state = static_cast<int32_t>(word & 0xFF);
  out->port_state = static_cast<int32_t>((word >> 8) & 0xFF);
  out->offset_ns = static_cast<int64_t>(self.clock_offset_ns.load(std::memory_order_relaxed));
  out->path_delay_ns = static_cast<int64_t>(self.clock_path_delay_ns.load(std::memory_order_relaxed));
  return 0;
}

int ccomm_get_peer_clock_sized(const ccomm_client* c, int node, ccomm_peer_clock* out, size_t size) {
  ccomm_peer_clock pc{};
  return CopySized(FillPeerClock(c, node, &pc), pc, out, size);
}

int ccomm_get_clock_state_sized(const ccomm_client* c, ccomm_clock_state* out, size_t size) {
  ccomm_clock_state cs{};
  return CopySized(FillClockState(c, &cs), cs, out, size);
}

const char* ccomm_clock_state_name(int state) {
  static const char* const kNames[] = {"none", "syncing", "synced", "lost"};
  return state >= 0 && state < 4 ? kNames[state] : "?";
}

const char* ccomm_production_age_name(int code) {
  static const char* const kNames[] = {"synced", "same_node", "never", "local_unsynced", "producer_unsynced",
                                       "no_summary"};
  return code >= 0 && code < 6 ? kNames[code] : "?";
}

int ccomm_get_daemon_counter(const ccomm_client* c, int index, const char** name, uint64_t* value) {
  static const char* const kNames[] = {
      "frames_rx",         "frames_tx",          "frames_bad",      "frames_wrong_hash",
      "frames_unknown_sender", "frames_auth_failed", "frames_replayed", "frames_not_for_us",
      "entries_unknown_signal", "entries_wrong_type", "send_errors",  "tx_wakeups",
      "recv_errors",       "slots_reclaimed",    "socket_drops",    "frames_wrong_source",
      "frames_foreign",    "cycle_rounds",       "cycle_late",      "cycle_etf_drops",
      "cycle_launch"};
  static_assert(sizeof(kNames) / sizeof(kNames[0]) == st::kDaemonCounterCount, "one name per DaemonCounter");
  if (!c || index < 0 || static_cast<uint32_t>(index) >= st::kDaemonCounterCount) return CCOMM_E_INVAL;
  if (name) *name = kNames[index];
  if (value) *value = SegmentOf(c).header()->daemon_counters[index].load(std::memory_order_relaxed);
  return 0;
}

uint32_t ccomm_daemon_generation(const ccomm_client* c) {
  return c ? SegmentOf(c).header()->generation.load(std::memory_order_relaxed) : 0;
}

}  // extern "C"
