// SPDX-License-Identifier: Apache-2.0
// ROS 2 -> ccomm: takes DDS samples one at a time into the route's preallocated sample,
// checks them whole (array length, layout, value range) and writes them into ccomm with
// one ccomm_write, so a bad sample is refused and counted and nothing is half-written.
// Also watches DDS discovery for writers that use a bridged topic name with another
// type (DDS never matches them, so they would fail silently).
#include <ctime>

#include <cstdio>
#include <cstring>

#include "bridge.h"
#include "common/public/platform_app.h"
#include "sample_layout.h"

namespace ccomm_ros2 {
namespace {

void SleepMs(int ms) { ccomm::platform::SleepNsInterruptible(static_cast<uint64_t>(ms) * 1000000u); }

enum class Verdict { kOk, kBadLength, kBadValue };

// A layout, when given, must describe exactly `count` elements in every dimension
// (std_msgs/MultiArrayLayout: dim[i].size multiply to the element count, dim[i].stride =
// dim[i].size * dim[i+1].stride, the last stride its size). Checking dim[0] alone let a
// 3x2 layout with 3 values through. Bounded: at most dim_._length steps, no allocation.
bool LayoutDescribes(const std_msgs_msg_dds__MultiArrayLayout_& layout, uint32_t count) {
  const uint32_t n = layout.dim_._length;
  if (n == 0) return true;  // no layout: a flat array
  uint64_t elements = 1;
  for (uint32_t i = n; i-- > 0;) {
    const std_msgs_msg_dds__MultiArrayDimension_& d = layout.dim_._buffer[i];
    elements *= d.size_;
    if (elements > count || d.stride_ != elements) return false;  // also stops any overflow
  }
  return elements == count;
}

// The value bytes of a taken sample, if the sample fits the signal.
Verdict Check(const Route& r, const void** value) {
  const uint32_t count = r.desc.count;
  const uint8_t* bytes;
  if (r.type->is_array) {
    const ArraySample* a = static_cast<const ArraySample*>(r.sample);
    if (a->data_.length != count || a->layout_.data_offset_ != 0) return Verdict::kBadLength;
    if (!LayoutDescribes(a->layout_, count)) return Verdict::kBadLength;
    bytes = static_cast<const uint8_t*>(a->data_.buffer);
  } else {
    bytes = static_cast<const uint8_t*>(r.sample);
  }
  if (r.desc.type == CCOMM_BOOL)  // UInt8MultiArray/Bool carry 0 or 1 only
    for (uint32_t i = 0; i < count; ++i)
      if (bytes[i] > 1) return Verdict::kBadValue;
  *value = bytes;
  return Verdict::kOk;
}

// Writes one checked value; waits out a full event queue (ccommd catching up) for up to
// a second rather than drop the event. Returns a ccomm error that needs a reopen.
int WriteValue(Bridge* b, ccomm_client* c, Route* r, const void* value) {
  for (int waited = 0;; ++waited) {
    int rc = ccomm_write(c, r->id, value, r->desc.value_bytes);
    if (rc == 0) {
      r->n.written.fetch_add(1, std::memory_order_relaxed);
      return 0;
    }
    if (rc == CCOMM_E_RETIRED || rc == CCOMM_E_VERSION) return rc;
    if ((rc != CCOMM_E_FULL && rc != CCOMM_E_BUSY) || waited >= 1000 || b->stop.load()) {
      r->n.ccomm_errors.fetch_add(1, std::memory_order_relaxed);
      if (b->opt.verbose) fprintf(stderr, "ccomm-ros2: %s: write: %s\n", r->name.c_str(), ccomm_strerror(rc));
      return 0;
    }
    SleepMs(1);
  }
}

// Takes every available sample of one route. Returns a ccomm error needing a reopen;
// the sample that met it is kept in r->sample and written again after the reopen.
int Drain(Bridge* b, ccomm_client* c, Route* r, bool* pending) {
  for (;;) {
    if (*pending) {
      const void* value = nullptr;
      if (Check(*r, &value) == Verdict::kOk) {
        int rc = WriteValue(b, c, r, value);
        if (rc < 0) return rc;
      }
      *pending = false;
    }
    void* buf[1] = {r->sample};
    dds_sample_info_t si;
    dds_return_t n = dds_take(r->endpoint, buf, &si, 1, 1);
    if (n < 0) {
      r->n.dds_errors.fetch_add(1, std::memory_order_relaxed);
      return 0;
    }
    if (n == 0) return 0;
    if (!si.valid_data) continue;  // a writer went away (dispose/unregister notice)
    r->n.received.fetch_add(1, std::memory_order_relaxed);
    const void* value = nullptr;
    switch (Check(*r, &value)) {
      case Verdict::kBadLength:
        r->n.refused_length.fetch_add(1, std::memory_order_relaxed);
        if (b->opt.verbose) fprintf(stderr, "ccomm-ros2: %s: refused a sample of the wrong length\n", r->name.c_str());
        continue;
      case Verdict::kBadValue:
        r->n.refused_value.fetch_add(1, std::memory_order_relaxed);
        if (b->opt.verbose) fprintf(stderr, "ccomm-ros2: %s: refused a sample with a value that is not 0 or 1\n", r->name.c_str());
        continue;
      case Verdict::kOk: break;
    }
    *pending = true;
  }
}

// DDS discovery: a writer on one of our topics with another type.
void CheckPublications(Bridge* b, dds_entity_t builtin) {
  void* ptrs[16] = {nullptr};
  dds_sample_info_t si[16];
  for (;;) {
    dds_return_t n = dds_take(builtin, ptrs, si, 16, 16);
    if (n <= 0) return;
    for (int i = 0; i < n; ++i) {
      if (!si[i].valid_data || si[i].instance_state != DDS_ALIVE_INSTANCE_STATE) continue;
      const dds_builtintopic_endpoint_t* ep = static_cast<const dds_builtintopic_endpoint_t*>(ptrs[i]);
      for (std::vector<Route*>* list : {&b->to_ros, &b->from_ros})
        for (Route* r : *list)
          if (ep->topic_name && ep->type_name && r->topic == ep->topic_name &&
              strcmp(ep->type_name, r->type->desc->m_typename) != 0) {
            r->n.wrong_type_peers.fetch_add(1, std::memory_order_relaxed);
            fprintf(stderr, "ccomm-ros2: %s: ignoring a DDS writer of type %s on %s (the signal is %s)\n",
                    r->name.c_str(), ep->type_name, r->topic.c_str(), r->type->desc->m_typename);
          }
    }
    dds_return_loan(builtin, ptrs, n);
  }
}

}  // namespace

void RunFromRos(Bridge* b) {
  dds_entity_t ws = dds_create_waitset(b->participant);
  dds_entity_t builtin = dds_create_reader(b->participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  if (ws < 0 || builtin < 0) {
    fprintf(stderr, "ccomm-ros2: cannot watch DDS discovery: %s\n", dds_strretcode(ws < 0 ? ws : builtin));
    b->fatal = 1;
    b->stop = true;
    return;
  }
  dds_entity_t builtin_cond = dds_create_readcondition(builtin, DDS_ANY_STATE);
  dds_waitset_attach(ws, builtin_cond, -1);
  std::vector<dds_entity_t> conds;
  for (size_t i = 0; i < b->from_ros.size(); ++i) {
    conds.push_back(dds_create_readcondition(b->from_ros[i]->endpoint, DDS_ANY_STATE));
    dds_waitset_attach(ws, conds.back(), static_cast<dds_attach_t>(i));
  }
  ccomm_client* c = nullptr;
  if (!b->from_ros.empty()) {
    c = OpenWaiting(b);
    if (c && !ResolveRoutes(b, c, b->from_ros)) { b->fatal = 1; b->stop = true; }
  }
  std::vector<char> pending(b->from_ros.size(), 0);
  while (c || b->from_ros.empty()) {
    if (b->stop.load(std::memory_order_relaxed)) break;
    dds_waitset_wait(ws, nullptr, 0, DDS_MSECS(100));  // 100 ms to notice stop
    CheckPublications(b, builtin);
    for (size_t i = 0; c && i < b->from_ros.size();) {
      bool p = pending[i] != 0;
      int err = Drain(b, c, b->from_ros[i], &p);
      pending[i] = p;
      if (err != CCOMM_E_RETIRED && err != CCOMM_E_VERSION) {
        ++i;
        continue;
      }
      // ccommd replaced the segment: attach anew, then the same route again (its pending
      // sample is written into the new segment).
      if (b->opt.verbose) fprintf(stderr, "ccomm-ros2: segment retired, reopening\n");
      ccomm_close(c);
      c = OpenWaiting(b);
      if (c && !ResolveRoutes(b, c, b->from_ros)) { b->fatal = 1; b->stop = true; break; }
      if (c) b->reopens.fetch_add(1, std::memory_order_relaxed);
    }
  }
  if (c) ccomm_close(c);
  dds_delete(ws);
}

}  // namespace ccomm_ros2
