// SPDX-License-Identifier: Apache-2.0
// libccomm's introspection calls (ccomm.h): error texts, signal descriptions, statistics
// and the daemon's state. None is on a control loop's path; all read the segment through
// the handle's public view of it (client_internal.h), like history.cpp.
#include <stdint.h>

#include "ccomm/ccomm.h"
#include "client/client_internal.h"
#include "common/platform.h"
#include "store/segment.h"

namespace {

namespace st = ccomm::store;
namespace platform = ccomm::platform;
using ccomm::client::SegmentOf;

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

int ccomm_describe(const ccomm_client* c, ccomm_signal s, ccomm_signal_desc* out) {
  if (!ValidSignal(c, s) || !out) return CCOMM_E_INVAL;
  const st::Segment& seg = SegmentOf(c);
  const st::SignalDirectoryEntry& d = seg.dir(static_cast<uint32_t>(s));
  out->name = d.name;
  out->type = d.type;
  out->count = d.count;
  out->value_bytes = d.value_bytes;
  out->is_event = (d.flags & st::kSigEvent) ? 1 : 0;
  out->produced_here = (d.flags & st::kSigProducedHere) ? 1 : 0;
  out->consumed_here = (d.flags & st::kSigConsumedHere) ? 1 : 0;
  out->stale_after_ms = d.stale_after_ms;
  out->producer = d.producer < seg.node_count() ? seg.node_name(d.producer) : "";
  return 0;
}

int ccomm_daemon_alive(const ccomm_client* c) {
  if (!c) return 0;
  const st::SegmentHeader* h = SegmentOf(c).header();
  if (h->daemon_pid.load(std::memory_order_acquire) == 0) return 0;
  uint64_t hb = h->daemon_heartbeat_ns.load(std::memory_order_acquire);
  return platform::MonotonicNs() - hb < 1000000000ull ? 1 : 0;
}

int ccomm_get_signal_stats(const ccomm_client* c, ccomm_signal s, ccomm_signal_stats* out) {
  if (!ValidSignal(c, s) || !out) return CCOMM_E_INVAL;
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
  out->stale = (d.flags & st::kSigConsumedHere) && stale_ns &&
               (!last || static_cast<uint64_t>(Age(now, last)) > stale_ns);
  return 0;
}

int ccomm_node_count(const ccomm_client* c) { return c ? static_cast<int>(SegmentOf(c).node_count()) : CCOMM_E_INVAL; }

int ccomm_get_peer_stats(const ccomm_client* c, int node, ccomm_peer_stats* out) {
  if (!c || !out || node < 0 || static_cast<uint32_t>(node) >= SegmentOf(c).node_count()) return CCOMM_E_INVAL;
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

int ccomm_get_peer_clock(const ccomm_client* c, int node, ccomm_peer_clock* out) {
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

int ccomm_get_clock_state(const ccomm_client* c, ccomm_clock_state* out) {
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

const char* ccomm_clock_state_name(int state) {
  static const char* const kNames[] = {"none", "syncing", "synced", "lost"};
  return state >= 0 && state < 4 ? kNames[state] : "?";
}

int ccomm_get_daemon_counter(const ccomm_client* c, int index, const char** name, uint64_t* value) {
  static const char* const kNames[] = {
      "frames_rx",         "frames_tx",          "frames_bad",      "frames_wrong_hash",
      "frames_unknown_sender", "frames_auth_failed", "frames_replayed", "frames_not_for_us",
      "entries_unknown_signal", "entries_wrong_type", "send_errors",  "tx_wakeups",
      "recv_errors",       "slots_reclaimed",    "socket_drops",    "frames_wrong_source"};
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
