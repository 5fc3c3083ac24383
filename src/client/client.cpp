// SPDX-License-Identifier: Apache-2.0
// libccomm: the real-time calls of the C API (ccomm.h): read, write, flush, set_time,
// wait. Reads and writes touch only the signal's lines in the mapped segment and the
// handle's preallocated, per-signal state (HandleSignal, client_handle.h). Opening a
// handle is client_open.cpp; statistics and descriptions client_info.cpp.
#include "ccomm/ccomm.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "client/client_handle.h"
#include "client/doorbell.h"
#include "common/platform.h"
#include "common/value_type.h"
#include "store/freshness.h"
#include "store/reclaim.h"
#include "store/segment.h"

using ccomm::store::RingCursor;
using ccomm::store::Segment;
using ccomm::store::SignalDirectoryEntry;
using ccomm::store::SlotMeta;
using ccomm::store::StoreResult;
namespace st = ccomm::store;

namespace {

// The public type codes are the store's and the wire's (common/value_type.h).
static_assert(CCOMM_BOOL == static_cast<int>(ccomm::ValueType::kBool) &&
                  CCOMM_INT32 == static_cast<int>(ccomm::ValueType::kInt32) &&
                  CCOMM_UINT32 == static_cast<int>(ccomm::ValueType::kUint32) &&
                  CCOMM_INT64 == static_cast<int>(ccomm::ValueType::kInt64) &&
                  CCOMM_FLOAT == static_cast<int>(ccomm::ValueType::kFloat) &&
                  CCOMM_DOUBLE == static_cast<int>(ccomm::ValueType::kDouble),
              "ccomm_type must match common/value_type.h");

// Reads a state through the handle's cache (see StateCache). The change words are read
// before the copy, so the copy is at least as new as they say; if they move during
// the copy, the next read copies again.
// A value copy: one load and store for the common 8-byte value, not a library call.
inline void CopyValue(void* dst, const void* src, uint32_t n) {
  if (n == 8) memcpy(dst, src, 8);
  else memcpy(dst, src, n);
}

// The cache's value and meta are the read's result: a new value is copied from the cell
// into the cache once (the stamp taken before it, its inline word being the copy's
// first look: StateReadStamped), and either way the caller takes meta from the cache.
// A failed copy leaves no stamp, so the cache is never taken for a damaged copy.
__attribute__((always_inline)) inline StoreResult ReadState(HandleSignal& h, void* value, const SlotMeta** meta) {
  StateCache& k = h.cache;
  const st::StateStamp stamp = st::StateStampOf(h.state);
  *meta = &k.meta;
  if (stamp.version && stamp == k.stamp) {
    CopyValue(value, k.value, h.value_bytes);
    return StoreResult::kOk;
  }
  const StoreResult r = h.value_bytes == 8 ? st::StateReadStamped(h.state, stamp, k.value, &k.meta, 8)
                                           : st::StateReadStamped(h.state, stamp, k.value, &k.meta, h.value_bytes);
  if (r == StoreResult::kOk) {
    k.stamp = stamp;
    CopyValue(value, k.value, h.value_bytes);
  } else {
    k.stamp.version = 0;  // the cache may hold part of a refused copy
  }
  return r;
}

uint64_t Now(const ccomm_client* c) { return c->cycle_ns ? c->cycle_ns : ccomm::platform::MonotonicNs(); }

// CCOMM_OPEN_BATCH: stores the value a step holds for `h` (stamped with its write time)
// and counts the write or its failure. False if the store refused it.
bool StorePending(HandleSignal& h) {
  if (ccomm::store::StateWrite(h.state, h.pending, 0, h.pending_ns, h.pending_ns) != StoreResult::kOk) {
    h.stats->write_errors.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  h.stats->writes.fetch_add(1, std::memory_order_relaxed);
  return true;
}

// Age of a value stored at `stored_ns` as seen at `now`: 0 if it arrived after `now`
// (a cycle time taken before it arrived).
int64_t Age(uint64_t now, uint64_t stored_ns) { return now > stored_ns ? static_cast<int64_t>(now - stored_ns) : 0; }

// The signal `s` of handle `c`, or null for a bad handle or id.
HandleSignal* Sig(const ccomm_client* c, ccomm_signal s) {
  return c && s >= 0 && static_cast<uint32_t>(s) < c->signal_count ? &c->sig[s] : nullptr;
}

bool Retired(const ccomm_client* c) {
  return c->segment.header()->state.load(std::memory_order_relaxed) == st::kRetired;
}

void FillNever(ccomm_info* info) {
  if (!info) return;
  info->status = CCOMM_NEVER;
  info->flags = 0;
  info->seq = 0;
  info->age_ns = -1;
  info->source_time_ns = 0;
}

// A signal's change counter: `latest` of a state, `published` of an event ring.
uint64_t ChangeCounter(const HandleSignal& h) {
  if (h.flags & st::kSigEvent) return st::RingChangeCount(h.ring);
  return st::StateChangeCount(h.state);
}

}  // namespace

bool ccomm::client::TakeChanges(ccomm_client* c) {
  bool changed = false;
  for (uint32_t i = 0; i < c->signal_count; ++i) {
    uint64_t v = ChangeCounter(c->sig[i]);
    if (v != c->sig[i].seen) changed = true;
    c->sig[i].seen = v;
  }
  return changed;
}

extern "C" {

namespace {

// The status and ccomm_info of a state read that ended with r (meta: the value's, if kOk).
__attribute__((always_inline)) inline int FinishState(HandleSignal* h, void* value, ccomm_info* info, StoreResult r,
                                                      const SlotMeta& meta, uint64_t now) {
  if (r == StoreResult::kBusy) return CCOMM_E_BUSY;
  if (r == StoreResult::kCorrupt) {
    h->stats->corrupt.fetch_add(1, std::memory_order_relaxed);
    return CCOMM_E_CORRUPT;
  }
  int status;
  int64_t age = -1;
  if (r == StoreResult::kNever) {
    status = CCOMM_NEVER;
  } else {
    age = Age(now, meta.local_time_ns);
    status = st::IsStale(true, static_cast<uint64_t>(age), h->stale_ns) ? CCOMM_STALE : CCOMM_FRESH;
  }
  uint32_t flags = 0;
  if (status != CCOMM_FRESH && h->safe_value) {
    memcpy(value, h->safe_value, h->value_bytes);
    flags |= CCOMM_INFO_SAFE_VALUE;
  }
  if (info) {
    info->status = status;
    info->flags = flags;
    info->seq = r == StoreResult::kOk ? meta.value_seq : 0;
    info->age_ns = age;
    info->source_time_ns = r == StoreResult::kOk ? meta.source_time_ns : 0;
    info->lost = h->stats->lost.load(std::memory_order_relaxed);
  }
  return status;
}

// ReadState8's rare cases, as tail calls out of its line (so that its common path keeps
// nothing across a call): the inline copy was not usable or moved (StateRead from the
// start), or a read that found no fresh value.
__attribute__((noinline)) int FinishStateSlow(HandleSignal* h, void* value, ccomm_info* info, StoreResult r,
                                              uint64_t now) {
  return FinishState(h, value, info, r, h->cache.meta, now);
}
__attribute__((noinline)) int ReadState8Slow(ccomm_client* c, HandleSignal* h, void* value, ccomm_info* info,
                                             st::StateStamp stamp) {
  StateCache& k = h->cache;
  const StoreResult r = st::StateReadCopies(h->state, k.value, &k.meta, 8);
  k.stamp = stamp;
  if (r != StoreResult::kOk) k.stamp.version = 0;  // the cache may hold part of a refused copy
  else memcpy(value, k.value, 8);
  return FinishState(h, value, info, r, k.meta, Now(c));
}

// ccomm_read of a state holding one 8-byte value (double, int64: h->read8_type), the
// control loop's read: ReadState and FinishState with the size known, the cell's two
// words compared with the cache and, when they moved, the inline copy read from the
// words just loaded; the rest out of line.
__attribute__((always_inline)) inline int ReadState8(ccomm_client* c, HandleSignal* h, void* value,
                                                     ccomm_info* info) {
  if (Retired(c)) return CCOMM_E_RETIRED;
  StateCache& k = h->cache;
  const st::StateView v = h->state;  // the cell's address once, not again after each acquire load
  const st::StateStamp stamp = st::StateStampOf(v, 8);
  if (!(stamp.version && stamp == k.stamp)) {
    const st::CopyResult cr = st::StateReadInlineStamped(v, stamp, k.value, &k.meta, 8);
    if (__builtin_expect(cr != st::CopyResult::kOk, 0)) {
      if (cr != st::CopyResult::kCorrupt) return ReadState8Slow(c, h, value, info, stamp);
      k.stamp.version = 0;  // the cache holds part of a refused copy
      return FinishStateSlow(h, value, info, StoreResult::kCorrupt, 0);
    }
    k.stamp = stamp;
  }
  memcpy(value, k.value, 8);
  const uint64_t now = Now(c);
  const int64_t age = Age(now, k.meta.local_time_ns);
  if (__builtin_expect(st::IsStale(true, static_cast<uint64_t>(age), h->stale_ns), 0))
    return FinishStateSlow(h, value, info, StoreResult::kOk, now);
  if (info) {
    info->status = CCOMM_FRESH;
    info->flags = 0;
    info->seq = k.meta.value_seq;
    info->age_ns = age;
    info->source_time_ns = k.meta.source_time_ns;
    info->lost = h->stats->lost.load(std::memory_order_relaxed);
  }
  return CCOMM_FRESH;
}

// ccomm_read after its argument checks; the typed reads call it directly (no second
// check, no call through the PLT).
__attribute__((always_inline)) inline int ReadSignal(ccomm_client* c, HandleSignal* h, void* value,
                                                     ccomm_info* info) {
  if (Retired(c)) return CCOMM_E_RETIRED;
  SlotMeta meta;
  const uint64_t now = Now(c);

  if (h->flags & st::kSigEvent) {
    RingCursor& cur = h->cursor;
    uint64_t lost_before = cur.lost;
    StoreResult r = ccomm::store::RingRead(h->ring, &cur, value, &meta, now);
    if (r == StoreResult::kCorrupt) {  // skipped (counted lost for this handle), never returned
      h->stats->corrupt.fetch_add(1, std::memory_order_relaxed);
      return CCOMM_E_CORRUPT;
    }
    if (cur.lost != lost_before) h->stats->overflow.fetch_add(cur.lost - lost_before, std::memory_order_relaxed);
    if (r != StoreResult::kOk) {
      if (info) {
        FillNever(info);
        info->status = CCOMM_EMPTY;
        info->lost = cur.lost + h->stats->lost.load(std::memory_order_relaxed);
      }
      return CCOMM_EMPTY;
    }
    if (info) {
      info->status = CCOMM_FRESH;
      info->flags = 0;
      info->seq = meta.value_seq;
      info->age_ns = Age(now, meta.local_time_ns);
      info->source_time_ns = meta.source_time_ns;
      info->lost = cur.lost + h->stats->lost.load(std::memory_order_relaxed);
    }
    return CCOMM_FRESH;
  }

  const SlotMeta* m = nullptr;
  const StoreResult r = ReadState(*h, value, &m);
  return FinishState(h, value, info, r, *m, now);
}

// ReadSignal as a call: the 8-byte typed reads keep their ReadState8 line free of it.
__attribute__((noinline)) int ReadSignalOutOfLine(ccomm_client* c, HandleSignal* h, void* value, ccomm_info* info) {
  return ReadSignal(c, h, value, info);
}

}  // namespace

int ccomm_read(ccomm_client* c, ccomm_signal s, void* value, size_t len, ccomm_info* info) {
  HandleSignal* h = Sig(c, s);
  if (!h || !value) return CCOMM_E_INVAL;
  if (len != h->value_bytes) return CCOMM_E_TYPE;
  return ReadSignal(c, h, value, info);
}

int ccomm_write(ccomm_client* c, ccomm_signal s, const void* value, size_t len) {
  HandleSignal* h = Sig(c, s);
  if (!h || !value) return CCOMM_E_INVAL;
  if (len != h->value_bytes) return CCOMM_E_TYPE;
  if (!(h->flags & st::kSigProducedHere)) return CCOMM_E_PERM;
  if (Retired(c)) return CCOMM_E_RETIRED;
  const uint64_t now = Now(c);
  if (h->pending) {
    // A batch step's state output is kept in the handle until ccomm_flush stores it with
    // the step's other outputs: ccommd, woken by anyone, cannot send half a step or mix
    // this step's value with the last step's (see PublishStep).
    if (h->has_pending) {
      // The step writes this signal again: its earlier value is stored now, so that the
      // newer one replacing it shows as a gap in the sequence (coalesced, as without
      // batch), never as a value that silently did not exist.
      StorePending(*h);
    }
    memcpy(h->pending, value, h->value_bytes);
    h->pending_ns = now;
    if (!h->has_pending) {
      h->has_pending = true;
      c->pending_states[static_cast<uint32_t>(s) / 64] |= 1ull << (static_cast<uint32_t>(s) % 64);
    }
    if ((h->flags & st::kSigForwarded) && !(h->flags & st::kSigPeriodic)) c->pending_tx = true;
    c->pending_rx = true;
    return 0;
  }
  StoreResult r = (h->flags & st::kSigEvent) ? ccomm::store::RingWrite(h->ring, value, 0, now, now)
                                             : ccomm::store::StateWrite(h->state, value, 0, now, now);
  if (r != StoreResult::kOk) {
    h->stats->write_errors.fetch_add(1, std::memory_order_relaxed);
    return r == StoreResult::kFull ? CCOMM_E_FULL : CCOMM_E_BUSY;
  }
  h->stats->writes.fetch_add(1, std::memory_order_relaxed);
  const bool ring = !(c->flags & (CCOMM_OPEN_NO_DOORBELL | CCOMM_OPEN_BATCH));
  // Periodic signals leave on ccommd's period: no dirty bit, no doorbell for them.
  if ((h->flags & st::kSigForwarded) && !(h->flags & st::kSigPeriodic)) {
    const uint32_t id = static_cast<uint32_t>(s);
    if (c->flags & CCOMM_OPEN_BATCH) {
      // Not in the shared dirty map yet: a doorbell rung by another handle must not send
      // part of this cycle. The flush hands them over at once.
      c->pending_dirty[id / 64] |= 1ull << (id % 64);
      c->pending_tx = true;
    } else {
      ccomm::client::DoorbellNotifyTx(c->doorbell, id, ring);
    }
  }
  // Waiters are woken now (no write to shared lines unless someone waits), at the
  // flush (batch), or see the change when they next wait or time out (no doorbell).
  if (ring) ccomm::client::DoorbellNotifyRx(c->doorbell);
  else if (c->flags & CCOMM_OPEN_BATCH) c->pending_rx = true;
  return 0;
}

#define CCOMM_TYPED(suffix, ctype, code)                                                     \
  int ccomm_read_##suffix(ccomm_client* c, ccomm_signal s, ctype* v, ccomm_info* info) {     \
    /* Sig(), with one compare for a negative or too large s */                              \
    if (!c || static_cast<uint32_t>(s) >= c->signal_count || !v) return CCOMM_E_INVAL;       \
    HandleSignal* h = &c->sig[s];                                                            \
    if (sizeof(ctype) == 8 && h->read8_type == (code)) return ReadState8(c, h, v, info);     \
    if (h->type != (code) || h->count != 1) return CCOMM_E_TYPE;                             \
    if (sizeof(ctype) == 8) return ReadSignalOutOfLine(c, h, v, info);                       \
    return ReadSignal(c, h, v, info);                                                        \
  }                                                                                          \
  int ccomm_write_##suffix(ccomm_client* c, ccomm_signal s, ctype v) {                       \
    const HandleSignal* h = Sig(c, s);                                                       \
    if (!h) return CCOMM_E_INVAL;                                                            \
    if (h->type != (code) || h->count != 1) return CCOMM_E_TYPE;                             \
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
  const HandleSignal* h = Sig(c, s);
  if (!h || !v) return CCOMM_E_INVAL;
  if (h->type != CCOMM_BOOL || h->count != 1) return CCOMM_E_TYPE;
  uint8_t b = 0;
  int r = ccomm_read(c, s, &b, 1, info);
  *v = b ? 1 : 0;
  return r;
}

int ccomm_write_bool(ccomm_client* c, ccomm_signal s, int v) {
  const HandleSignal* h = Sig(c, s);
  if (!h) return CCOMM_E_INVAL;
  if (h->type != CCOMM_BOOL || h->count != 1) return CCOMM_E_TYPE;
  uint8_t b = v ? 1 : 0;
  return ccomm_write(c, s, &b, 1);
}

namespace {

// The batch step: stores every pending state value (then marks them dirty with the step's
// events, below). Bounded: signal_count / 64 words. Returns the first store error.
int PublishStep(ccomm_client* c) {
  int result = 0;
  bool any = false;
  for (uint32_t w = 0; w < (c->signal_count + 63) / 64 && !any; ++w) any = c->pending_states[w] != 0;
  if (!any) return 0;
  c->segment.BeginStep();  // ccommd collecting meanwhile refreshes what it took (send_path.cpp, SettleSteps)
  for (uint32_t w = 0; w < (c->signal_count + 63) / 64; ++w) {
    uint64_t bits = c->pending_states[w];
    c->pending_states[w] = 0;
    while (bits) {
      const uint32_t id = w * 64 + static_cast<uint32_t>(__builtin_ctzll(bits));
      bits &= bits - 1;
      HandleSignal& h = c->sig[id];
      h.has_pending = false;
      if (!StorePending(h)) {
        if (!result) result = CCOMM_E_BUSY;
        continue;
      }
      if ((h.flags & st::kSigForwarded) && !(h.flags & st::kSigPeriodic)) c->pending_dirty[w] |= 1ull << (id % 64);
    }
  }
  c->segment.EndStep();
  return result;
}

}  // namespace

int ccomm_flush(ccomm_client* c) {
  if (!c) return CCOMM_E_INVAL;
  const int stored = (c->flags & CCOMM_OPEN_BATCH) ? PublishStep(c) : 0;
  const bool quiet = (c->flags & CCOMM_OPEN_NO_DOORBELL) != 0;  // no syscall, even here
  if (c->pending_tx) {
    // Bounded: signal_count / 64 words (at most 64).
    for (uint32_t w = 0; w < (c->signal_count + 63) / 64; ++w) {
      if (!c->pending_dirty[w]) continue;
      c->segment.MarkDirtyWord(w, c->pending_dirty[w]);
      c->pending_dirty[w] = 0;
    }
    if (quiet) c->segment.header()->tx_doorbell.fetch_add(1, std::memory_order_release);
    else ccomm::client::DoorbellRingTx(c->doorbell);
  }
  if (c->pending_rx && !quiet) ccomm::client::DoorbellNotifyRx(c->doorbell);
  c->pending_tx = c->pending_rx = false;
  return stored;
}

int ccomm_set_time(ccomm_client* c, int64_t t_ns) {
  if (!c || t_ns < 0) return CCOMM_E_INVAL;
  c->cycle_ns = static_cast<uint64_t>(t_ns);
  return 0;
}

int64_t ccomm_now(void) { return static_cast<int64_t>(ccomm::platform::MonotonicNs()); }

int ccomm_wait(ccomm_client* c, int timeout_ms) {
  if (!c) return CCOMM_E_INVAL;
  st::SegmentHeader* h = c->segment.header();
  // Register first, then look (see SegmentHeader::rx_waiters): a write this look
  // misses has seen us waiting and bumps the doorbell, so DoorbellWait returns at once.
  // This process's share of rx_waiters is kept in its entry too, so that ccommd can take
  // it back if the process dies waiting (layout.h, WaiterEntry); first rx_waiters, then
  // the entry (and back in reverse), so that a take-back never exceeds what was added.
  st::WaiterEntry* me = st::ClaimWaiterEntry(h, ccomm::platform::ProcessId());
  h->rx_waiters.fetch_add(1, std::memory_order_seq_cst);
  if (me) me->waiting.fetch_add(1, std::memory_order_relaxed);
  uint32_t seen = h->rx_doorbell.load(std::memory_order_seq_cst);
  bool changed = ccomm::client::TakeChanges(c);
  const uint64_t deadline = ccomm::platform::MonotonicNs() + uint64_t(timeout_ms < 0 ? 0 : timeout_ms) * 1000000;
  // Bounded by the deadline; a wake-up for a change another waiter consumed, or a
  // signal, sleeps again.
  while (!changed) {
    // After the look at rx_doorbell: a retirement after it also bumps the doorbell, so
    // the wait below returns at once (UnlinkThenRetire).
    if (Retired(c)) {
      if (me) me->waiting.fetch_sub(1, std::memory_order_relaxed);
      h->rx_waiters.fetch_sub(1, std::memory_order_seq_cst);
      return CCOMM_E_RETIRED;
    }
    int64_t left = -1;
    if (timeout_ms >= 0) {
      uint64_t now = ccomm::platform::MonotonicNs();
      if (now >= deadline) break;
      left = static_cast<int64_t>(deadline - now);
    }
    ccomm::client::DoorbellWait(c->doorbell, seen, left);
    seen = h->rx_doorbell.load(std::memory_order_seq_cst);
    changed = ccomm::client::TakeChanges(c);
  }
  if (me) me->waiting.fetch_sub(1, std::memory_order_relaxed);
  h->rx_waiters.fetch_sub(1, std::memory_order_seq_cst);
  return changed ? 1 : 0;
}

}  // extern "C"
