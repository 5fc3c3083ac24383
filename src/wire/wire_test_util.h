// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the wire codec tests (wire_test, wire_malformed_test).
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "wire/wire.h"

namespace ccomm {
namespace wire {

using Bytes = std::vector<uint8_t>;

enum : uint8_t { kBool = 1, kInt32 = 2, kUint32 = 3, kInt64 = 4, kFloat = 5, kDouble = 6 };

inline size_t ElemSize(uint8_t type) {
  switch (type) {
    case kBool: return 1;
    case kInt32: case kUint32: case kFloat: return 4;
    default: return 8;
  }
}

// Host-order bytes of a value array.
template <typename T>
inline Bytes HostBytes(std::initializer_list<T> values) {
  Bytes b(values.size() * sizeof(T));
  size_t i = 0;
  for (T v : values) std::memcpy(b.data() + sizeof(T) * i++, &v, sizeof(T));
  return b;
}

// Decodes from a heap buffer of exactly data.size() bytes (nullptr when empty).
// The tests decode through it, so under ASan any read past the frame's end fails them.
inline DecodeError DecodeExact(const Bytes& data, FrameHeader* h) {
  if (data.empty()) return DecodeHeader(nullptr, 0, h);
  std::unique_ptr<uint8_t[]> buf(new uint8_t[data.size()]);
  std::memcpy(buf.get(), data.data(), data.size());
  return DecodeHeader(buf.get(), data.size(), h);
}

inline DecodeError Decode(const Bytes& data) {
  FrameHeader h;
  return DecodeExact(data, &h);
}

struct EntryDef {
  uint16_t signal;
  uint8_t type;
  uint8_t flags;
  uint32_t seq;
  uint64_t time;
  Bytes value;  // host order (a fragment entry: its part only)
  uint16_t whole_count = 0;  // fragment entries: elements of the whole value
  uint32_t offset = 0;       // fragment entries: byte offset of the part
  uint16_t count() const {
    return (flags & kEntryFragment) ? whole_count : static_cast<uint16_t>(value.size() / ElemSize(type));
  }
};

// FrameWriter::Add or AddFragment, as the entry's flags say.
inline bool AddEntry(FrameWriter* w, uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, uint32_t seq,
              uint64_t time, uint32_t offset, const void* value, size_t len) {
  if (flags & kEntryFragment)
    return w->AddFragment(signal, type, static_cast<uint8_t>(flags & ~kEntryFragment), count, seq, time, offset,
                          value, len);
  return w->Add(signal, type, flags, count, seq, time, value, len);
}

struct FrameDef {
  FrameHeader h;
  std::vector<EntryDef> entries;
  Bytes tag;
};

inline FrameHeader Header(uint8_t flags, uint16_t sender, uint32_t seq, uint64_t time,
                   uint16_t dest = 0) {
  FrameHeader h;
  h.flags = flags;
  h.sender = sender;
  h.dest = dest;
  h.config_hash = 0x1234ABCD;
  h.seq = seq;
  h.send_time_ns = time;
  return h;
}

// Encodes with FrameWriter; a tag, if any, is appended as the protocol says.
inline Bytes Encode(const FrameDef& f) {
  Bytes buf(kMaxFrameSize);
  FrameWriter w(buf.data(), buf.size());
  w.Begin(f.h);
  for (const EntryDef& e : f.entries) {
    EXPECT_TRUE(AddEntry(&w, e.signal, e.type, e.flags, e.count(), e.seq, e.time, e.offset, e.value.data(),
                         e.value.size()));
  }
  const size_t n = w.Finish();
  EXPECT_GT(n, 0u);
  buf.resize(n);
  buf.insert(buf.end(), f.tag.begin(), f.tag.end());
  return buf;
}

// Contents of the valid vectors of docs/protocol.md (wire_test checks them against the
// document); scripts/wire_vectors.py defines the same independently.
inline std::map<std::string, FrameDef> ValidVectors() {
  std::map<std::string, FrameDef> v;
  v["heartbeat"] = {Header(kFlagHeartbeat, 2, 7, 1000000000, kDestAll), {}, {}};
  v["double"] = {Header(0, 1, 42, 2000000500, 2),
                 {{3, kDouble, 0, 9, 1999990000, HostBytes<double>({3.141592653589793})}},
                 {}};
  const uint64_t t = 4999000000;
  v["setup"] = {Header(0, 0, 1, 5000000000, 1),
                {{0, kBool, 0, 1, t, HostBytes<uint8_t>({1})},
                 {1, kInt32, 0, 1, t, HostBytes<int32_t>({-1, 2, 300000})},
                 {2, kUint32, 0, 1, t, HostBytes<uint32_t>({0xDEADBEEF})},
                 {3, kInt64, 0, 1, t, HostBytes<int64_t>({-5000000000})},
                 {4, kFloat, 0, 1, t, HostBytes<float>({-1.25f})},
                 {5, kDouble, 0, 1, t, HostBytes<double>({-2.25})}},
                {}};
  v["event"] = {Header(0, 3, 100, 3000000000, 0),
                {{7, kUint32, kEntryEvent, 5, 2999999000, HostBytes<uint32_t>({17})}},
                {}};
  Bytes tag(16);
  for (size_t i = 0; i < tag.size(); ++i) tag[i] = static_cast<uint8_t>(i);
  v["auth"] = {Header(kFlagAuth, 1, 43, 2000100000, 2),
               {{9, kInt64, 0, 10, 2000000000, HostBytes<int64_t>({-2})}},
               tag};
  v["fragment"] = {Header(0, 1, 44, 2000200000, 2),
                   {{10, kUint32, kEntryFragment, 11, 2000150000, HostBytes<uint32_t>({398, 399}), 400, 1592}},
                   {}};
  return v;
}

}  // namespace wire
}  // namespace ccomm
