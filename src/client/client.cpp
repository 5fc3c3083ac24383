// SPDX-License-Identifier: Apache-2.0
// libccomm: the C API (ccomm.h) over the shared-memory store. Reads and writes touch
// only the mapped segment and the handle's preallocated cursors.
#include "ccomm/ccomm.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <new>

#include "common/platform.h"
#include "config/config.h"
#include "store/segment.h"

using ccomm::store::RingCursor;
using ccomm::store::Segment;
using ccomm::store::SignalDirectoryEntry;
using ccomm::store::SlotMeta;
using ccomm::store::StoreResult;
namespace st = ccomm::store;

struct ccomm_client {
  Segment segment;
  uint32_t flags = 0;
  uint32_t signal_count = 0;
  RingCursor* cursors = nullptr;  // one per signal (used by event signals only)
  bool pending_tx = false;        // CCOMM_OPEN_BATCH: forwarded writes since the last flush
  bool pending_rx = false;        // CCOMM_OPEN_BATCH: any write since the last flush
};

namespace {

bool ValidSignal(const ccomm_client* c, ccomm_signal s) {
  return c && s >= 0 && static_cast<uint32_t>(s) < c->signal_count;
}

int MapError(int neg_errno) {
  if (neg_errno == -ENOENT) return CCOMM_E_NOENT;
  if (neg_errno == -EPROTO) return CCOMM_E_VERSION;
  errno = -neg_errno;
  return CCOMM_E_SYS;
}

void FillNever(ccomm_info* info) {
  if (!info) return;
  info->status = CCOMM_NEVER;
  info->flags = 0;
  info->seq = 0;
  info->age_ns = -1;
  info->source_time_ns = 0;
}

}  // namespace

extern "C" {

int ccomm_open(const char* node, uint32_t flags, ccomm_client** out) {
  if (!out) return CCOMM_E_INVAL;
  *out = nullptr;
  char host[ccomm::store::kNameBytes];
  if (!node || !*node) node = getenv("CCOMM_NODE");
  if (!node || !*node) {
    if (!ccomm::platform::HostName(host, sizeof host)) return CCOMM_E_SYS;
    node = host;
  }
  auto* c = new (std::nothrow) ccomm_client();
  if (!c) return CCOMM_E_SYS;
  int r = c->segment.Open(ccomm::store::SegmentName(node));
  if (r != 0) {
    delete c;
    return MapError(r);
  }
  c->flags = flags;
  c->signal_count = c->segment.signal_count();
  c->cursors = new (std::nothrow) RingCursor[c->signal_count ? c->signal_count : 1];
  if (!c->cursors) {
    delete c;
    return CCOMM_E_SYS;
  }
  for (uint32_t i = 0; i < c->signal_count; ++i)
    if (c->segment.dir(i).flags & st::kSigEvent)
      ccomm::store::RingSubscribe(c->segment.ring(i), &c->cursors[i]);
  *out = c;
  return 0;
}

void ccomm_close(ccomm_client* c) {
  if (!c) return;
  delete[] c->cursors;
  delete c;
}

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
    default: return "unknown code";
  }
}

ccomm_signal ccomm_find(ccomm_client* c, const char* name) {
  if (!c || !name) return CCOMM_E_INVAL;
  int id = c->segment.Find(name);
  return id < 0 ? CCOMM_E_NOENT : id;
}

int ccomm_signal_count(const ccomm_client* c) { return c ? static_cast<int>(c->signal_count) : CCOMM_E_INVAL; }

const char* ccomm_node_name(const ccomm_client* c) { return c ? c->segment.header()->node_name : nullptr; }

int ccomm_describe(const ccomm_client* c, ccomm_signal s, ccomm_signal_desc* out) {
  if (!ValidSignal(c, s) || !out) return CCOMM_E_INVAL;
  const SignalDirectoryEntry& d = c->segment.dir(static_cast<uint32_t>(s));
  out->name = d.name;
  out->type = d.type;
  out->count = d.count;
  out->value_bytes = d.value_bytes;
  out->is_event = (d.flags & st::kSigEvent) ? 1 : 0;
  out->produced_here = (d.flags & st::kSigProducedHere) ? 1 : 0;
  out->consumed_here = (d.flags & st::kSigConsumedHere) ? 1 : 0;
  out->stale_after_ms = d.stale_after_ms;
  out->producer = d.producer < c->segment.node_count() ? c->segment.node_name(d.producer) : "";
  return 0;
}

int ccomm_read(ccomm_client* c, ccomm_signal s, void* value, size_t len, ccomm_info* info) {
  if (!ValidSignal(c, s) || !value) return CCOMM_E_INVAL;
  const uint32_t id = static_cast<uint32_t>(s);
  const SignalDirectoryEntry& d = c->segment.dir(id);
  if (len != d.value_bytes) return CCOMM_E_TYPE;
  if (c->segment.header()->state.load(std::memory_order_relaxed) == st::kRetired) return CCOMM_E_RETIRED;
  SlotMeta meta;
  const uint64_t now = ccomm::platform::MonotonicNs();
  st::SignalStats& stats = c->segment.stats(id);

  if (d.flags & st::kSigEvent) {
    RingCursor& cur = c->cursors[id];
    uint64_t lost_before = cur.lost;
    StoreResult r = ccomm::store::RingRead(c->segment.ring(id), &cur, value, &meta, now);
    if (cur.lost != lost_before) stats.overflow.fetch_add(cur.lost - lost_before, std::memory_order_relaxed);
    if (r != StoreResult::kOk) {
      if (info) {
        FillNever(info);
        info->status = CCOMM_EMPTY;
        info->lost = cur.lost + stats.lost.load(std::memory_order_relaxed);
      }
      return CCOMM_EMPTY;
    }
    if (info) {
      info->status = CCOMM_FRESH;
      info->flags = 0;
      info->seq = meta.value_seq;
      info->age_ns = static_cast<int64_t>(now - meta.local_time_ns);
      info->source_time_ns = meta.source_time_ns;
      info->lost = cur.lost + stats.lost.load(std::memory_order_relaxed);
    }
    return CCOMM_FRESH;
  }

  StoreResult r = ccomm::store::StateRead(c->segment.state(id), value, &meta);
  if (r == StoreResult::kBusy) return CCOMM_E_BUSY;
  int status;
  int64_t age = -1;
  if (r == StoreResult::kNever) {
    status = CCOMM_NEVER;
  } else {
    age = static_cast<int64_t>(now - meta.local_time_ns);
    status = (d.stale_after_ms && age > static_cast<int64_t>(d.stale_after_ms) * 1000000) ? CCOMM_STALE
                                                                                       : CCOMM_FRESH;
  }
  uint32_t flags = 0;
  if (status != CCOMM_FRESH && (d.flags & st::kSigHasSafeValue)) {
    memcpy(value, c->segment.safe_value(id), d.value_bytes);
    flags |= CCOMM_INFO_SAFE_VALUE;
  }
  if (info) {
    info->status = status;
    info->flags = flags;
    info->seq = r == StoreResult::kOk ? meta.value_seq : 0;
    info->age_ns = age;
    info->source_time_ns = r == StoreResult::kOk ? meta.source_time_ns : 0;
    info->lost = stats.lost.load(std::memory_order_relaxed);
  }
  return status;
}

int ccomm_write(ccomm_client* c, ccomm_signal s, const void* value, size_t len) {
  if (!ValidSignal(c, s) || !value) return CCOMM_E_INVAL;
  const uint32_t id = static_cast<uint32_t>(s);
  const SignalDirectoryEntry& d = c->segment.dir(id);
  if (len != d.value_bytes) return CCOMM_E_TYPE;
  if (!(d.flags & st::kSigProducedHere)) return CCOMM_E_PERM;
  if (c->segment.header()->state.load(std::memory_order_relaxed) == st::kRetired) return CCOMM_E_RETIRED;
  const uint64_t now = ccomm::platform::MonotonicNs();
  StoreResult r = (d.flags & st::kSigEvent)
                      ? ccomm::store::RingWrite(c->segment.ring(id), value, 0, now, now)
                      : ccomm::store::StateWrite(c->segment.state(id), value, 0, now, now);
  st::SignalStats& stats = c->segment.stats(id);
  if (r != StoreResult::kOk) {
    stats.write_errors.fetch_add(1, std::memory_order_relaxed);
    return r == StoreResult::kFull ? CCOMM_E_FULL : CCOMM_E_BUSY;
  }
  stats.writes.fetch_add(1, std::memory_order_relaxed);
  const bool ring = !(c->flags & (CCOMM_OPEN_NO_DOORBELL | CCOMM_OPEN_BATCH));
  // Periodic signals leave on ccommd's period: no dirty bit, no doorbell for them.
  if ((d.flags & st::kSigForwarded) && !(d.flags & st::kSigPeriodic)) {
    if (c->flags & CCOMM_OPEN_BATCH) {
      c->segment.MarkDirty(id);
      c->pending_tx = true;
    } else {
      c->segment.NotifyTx(id, ring && !(d.flags & st::kSigPeriodic));
    }
  }
  if (ring) c->segment.NotifyRx();
  else if (c->flags & CCOMM_OPEN_BATCH) c->pending_rx = true;
  else c->segment.header()->rx_doorbell.fetch_add(1, std::memory_order_release);
  return 0;
}

#define CCOMM_TYPED(suffix, ctype, code)                                                     \
  int ccomm_read_##suffix(ccomm_client* c, ccomm_signal s, ctype* v, ccomm_info* info) {     \
    if (!ValidSignal(c, s) || !v) return CCOMM_E_INVAL;                                      \
    const SignalDirectoryEntry& d = c->segment.dir(static_cast<uint32_t>(s));                 \
    if (d.type != (code) || d.count != 1) return CCOMM_E_TYPE;                               \
    return ccomm_read(c, s, v, sizeof(ctype), info);                                         \
  }                                                                                          \
  int ccomm_write_##suffix(ccomm_client* c, ccomm_signal s, ctype v) {                       \
    if (!ValidSignal(c, s)) return CCOMM_E_INVAL;                                            \
    const SignalDirectoryEntry& d = c->segment.dir(static_cast<uint32_t>(s));                 \
    if (d.type != (code) || d.count != 1) return CCOMM_E_TYPE;                               \
    return ccomm_write(c, s, &v, sizeof(ctype));                                             \
  }

CCOMM_TYPED(double, double, CCOMM_DOUBLE)
CCOMM_TYPED(float, float, CCOMM_FLOAT)
CCOMM_TYPED(int32, int32_t, CCOMM_INT32)
CCOMM_TYPED(uint32, uint32_t, CCOMM_UINT32)
CCOMM_TYPED(int64, int64_t, CCOMM_INT64)
#undef CCOMM_TYPED

// bool is one byte in the segment and on the wire; the C API uses int for portability.
int ccomm_read_bool(ccomm_client* c, ccomm_signal s, int* v, ccomm_info* info) {
  if (!ValidSignal(c, s) || !v) return CCOMM_E_INVAL;
  const SignalDirectoryEntry& d = c->segment.dir(static_cast<uint32_t>(s));
  if (d.type != CCOMM_BOOL || d.count != 1) return CCOMM_E_TYPE;
  uint8_t b = 0;
  int r = ccomm_read(c, s, &b, 1, info);
  *v = b ? 1 : 0;
  return r;
}

int ccomm_write_bool(ccomm_client* c, ccomm_signal s, int v) {
  if (!ValidSignal(c, s)) return CCOMM_E_INVAL;
  const SignalDirectoryEntry& d = c->segment.dir(static_cast<uint32_t>(s));
  if (d.type != CCOMM_BOOL || d.count != 1) return CCOMM_E_TYPE;
  uint8_t b = v ? 1 : 0;
  return ccomm_write(c, s, &b, 1);
}

int ccomm_flush(ccomm_client* c) {
  if (!c) return CCOMM_E_INVAL;
  const bool quiet = (c->flags & CCOMM_OPEN_NO_DOORBELL) != 0;  // no syscall, even here
  if (c->pending_tx) {
    if (quiet) c->segment.header()->tx_doorbell.fetch_add(1, std::memory_order_release);
    else c->segment.RingTxDoorbell();
  }
  if (c->pending_rx) {
    if (quiet) c->segment.header()->rx_doorbell.fetch_add(1, std::memory_order_release);
    else c->segment.NotifyRx();
  }
  c->pending_tx = c->pending_rx = false;
  return 0;
}

int ccomm_wait(ccomm_client* c, int timeout_ms) {
  if (!c) return CCOMM_E_INVAL;
  st::SegmentHeader* h = c->segment.header();
  uint32_t seen = h->rx_doorbell.load(std::memory_order_seq_cst);
  h->rx_waiters.fetch_add(1, std::memory_order_seq_cst);
  bool woke = ccomm::platform::FutexWait(&h->rx_doorbell, seen,
                                         timeout_ms < 0 ? -1 : int64_t{timeout_ms} * 1000000);
  h->rx_waiters.fetch_sub(1, std::memory_order_seq_cst);
  return (woke || h->rx_doorbell.load(std::memory_order_acquire) != seen) ? 1 : 0;
}

int ccomm_daemon_alive(const ccomm_client* c) {
  if (!c) return 0;
  const st::SegmentHeader* h = c->segment.header();
  if (h->daemon_pid.load(std::memory_order_acquire) == 0) return 0;
  uint64_t hb = h->daemon_heartbeat_ns.load(std::memory_order_acquire);
  return ccomm::platform::MonotonicNs() - hb < 1000000000ull ? 1 : 0;
}

}  // extern "C"
