// SPDX-License-Identifier: Apache-2.0
// libccomm: opening and closing a handle (ccomm_open, ccomm_close) and finding signals.
// Everything a read or write needs later is resolved and allocated here, once, so the
// real-time calls (client.cpp) never allocate or walk the directory.
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <new>
#include <string>

#include "ccomm/ccomm.h"
#include "client/client_handle.h"
#include "client/doorbell.h"
#include "common/platform.h"
#include "store/segment.h"

using ccomm::store::Segment;
using ccomm::store::SignalDirectoryEntry;
namespace st = ccomm::store;

namespace {

// Bytes of the handle's copy of a signal's value (state signals only).
size_t CachedBytes(const SignalDirectoryEntry& d) { return (d.flags & st::kSigEvent) ? 0 : d.value_bytes; }

int MapError(int neg_errno) {
  if (neg_errno == -ENOENT) return CCOMM_E_NOENT;
  if (neg_errno == -EPROTO) return CCOMM_E_VERSION;
  errno = -neg_errno;
  return CCOMM_E_SYS;
}

}  // namespace

const Segment& ccomm::client::SegmentOf(const ccomm_client* c) { return c->segment; }

extern "C" {

int ccomm_open(const char* node, uint32_t flags, ccomm_client** out) {
  if (!out) return CCOMM_E_INVAL;
  *out = nullptr;
  char host[ccomm::store::kNameBytes];
  if (!node || !*node) node = getenv("CCOMM_NODE");
  const bool by_hostname = !node || !*node;
  if (by_hostname) {
    if (!ccomm::platform::HostName(host, sizeof host)) return CCOMM_E_SYS;
    node = host;
  }
  auto* c = new (std::nothrow) ccomm_client();
  if (!c) return CCOMM_E_SYS;
  int r = c->segment.Open(ccomm::store::SegmentName(node));
  if (r == -ENOENT && by_hostname) {
    // One image for every board: the hostname need not name the node (ccommd found it
    // by the board's MAC or IP). The board's only segment is its node's.
    const std::string prefix = ccomm::store::SegmentName("");
    char only[ccomm::store::kNameBytes];
    if (ccomm::platform::ListShm(prefix.c_str() + 1, only, sizeof only) == 1)
      r = c->segment.Open(ccomm::store::SegmentName(only));
  }
  if (r == 0) r = ccomm::client::DoorbellOpen(c->segment, &c->doorbell);
  if (r != 0) {
    ccomm::client::DoorbellClose(c->doorbell);
    delete c;
    return MapError(r);
  }
  c->flags = flags;
  c->signal_count = c->segment.signal_count();
  const uint32_t n = c->signal_count;
  c->sig = new (std::nothrow) HandleSignal[n ? n : 1];
  size_t cache_total = 0;
  for (uint32_t i = 0; i < n; ++i) {
    cache_total += CachedBytes(c->segment.dir(i));
    if (c->segment.safe_value(i)) cache_total += c->segment.dir(i).value_bytes;  // a private copy
    const SignalDirectoryEntry& d = c->segment.dir(i);
    if ((flags & CCOMM_OPEN_BATCH) && (d.flags & st::kSigProducedHere) && !(d.flags & st::kSigEvent))
      cache_total += d.value_bytes;  // the step's pending value
  }
  c->cache_bytes = new (std::nothrow) uint8_t[cache_total ? cache_total : 1];
  c->pending_dirty = new (std::nothrow) uint64_t[(n + 63) / 64 + 1]();
  c->pending_states = new (std::nothrow) uint64_t[(n + 63) / 64 + 1]();
  if (!c->sig || !c->cache_bytes || !c->pending_dirty || !c->pending_states) {
    ccomm_close(c);
    return CCOMM_E_SYS;
  }
  size_t off = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const SignalDirectoryEntry& d = c->segment.dir(i);
    HandleSignal& h = c->sig[i];
    h.flags = d.flags;
    h.value_bytes = d.value_bytes;
    h.count = d.count;
    h.type = d.type;
    h.stale_ns = uint64_t{d.stale_after_ms} * 1000000;
    h.stats = &c->segment.stats(i);
    if (const uint8_t* safe = c->segment.safe_value(i)) {
      // Copied at open: the segment is writable by every client, the safe value is not.
      memcpy(c->cache_bytes + off, safe, d.value_bytes);
      h.safe_value = c->cache_bytes + off;
      off += d.value_bytes;
    }
    if (d.flags & st::kSigEvent) {
      h.ring = c->segment.ring(i);
      ccomm::store::RingSubscribe(h.ring, &h.cursor);
    } else {
      h.state = c->segment.state(i);
      if (d.count == 1 && d.value_bytes == 8) h.read8_type = d.type;
    }
    if (size_t k = CachedBytes(d)) {
      h.cache.value = c->cache_bytes + off;
      off += k;
    }
    if ((flags & CCOMM_OPEN_BATCH) && (d.flags & st::kSigProducedHere) && !(d.flags & st::kSigEvent)) {
      h.pending = c->cache_bytes + off;
      off += d.value_bytes;
    }
  }
  ccomm::client::TakeChanges(c);  // ccomm_wait() waits for writes after the open
  ccomm::platform::ProcessId();  // fills the pid cache: the first write makes no syscall
  *out = c;
  return 0;
}

void ccomm_close(ccomm_client* c) {
  if (!c) return;
  ccomm::client::DoorbellClose(c->doorbell);
  delete[] c->sig;
  delete[] c->cache_bytes;
  delete[] c->pending_dirty;
  delete[] c->pending_states;
  delete c;
}

ccomm_signal ccomm_find(ccomm_client* c, const char* name) {
  if (!c || !name) return CCOMM_E_INVAL;
  int id = c->segment.Find(name);
  return id < 0 ? CCOMM_E_NOENT : id;
}

int ccomm_signal_count(const ccomm_client* c) { return c ? static_cast<int>(c->signal_count) : CCOMM_E_INVAL; }

const char* ccomm_node_name(const ccomm_client* c) { return c ? c->segment.header()->node_name : nullptr; }

}  // extern "C"
