// SPDX-License-Identifier: Apache-2.0
// Tests of the wire codec: the hex vectors of docs/protocol.md (read from the document
// itself), round trips, size limits, and rejection of every kind of malformed frame.
// Decoding always runs on a heap copy of exactly the frame's size, so under ASan any read
// past the end fails the test.
#include "wire/wire.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#ifndef CCOMM_SOURCE_DIR
#error "CCOMM_SOURCE_DIR must point at the source tree (set by src/wire/CMakeLists.txt)"
#endif

namespace ccomm {
namespace wire {
namespace {

using Bytes = std::vector<uint8_t>;

enum : uint8_t { kBool = 1, kInt32 = 2, kUint32 = 3, kInt64 = 4, kFloat = 5, kDouble = 6 };

size_t ElemSize(uint8_t type) {
  switch (type) {
    case kBool: return 1;
    case kInt32: case kUint32: case kFloat: return 4;
    default: return 8;
  }
}

// Host-order bytes of a value array.
template <typename T>
Bytes HostBytes(std::initializer_list<T> values) {
  Bytes b(values.size() * sizeof(T));
  size_t i = 0;
  for (T v : values) std::memcpy(b.data() + sizeof(T) * i++, &v, sizeof(T));
  return b;
}

// Decodes from a heap buffer of exactly data.size() bytes (nullptr when empty).
DecodeError DecodeExact(const Bytes& data, FrameHeader* h) {
  if (data.empty()) return DecodeHeader(nullptr, 0, h);
  std::unique_ptr<uint8_t[]> buf(new uint8_t[data.size()]);
  std::memcpy(buf.get(), data.data(), data.size());
  return DecodeHeader(buf.get(), data.size(), h);
}

DecodeError Decode(const Bytes& data) {
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
bool AddEntry(FrameWriter* w, uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, uint32_t seq,
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

FrameHeader Header(uint8_t flags, uint16_t sender, uint32_t seq, uint64_t time,
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
Bytes Encode(const FrameDef& f) {
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

// Checks that `data` decodes to exactly `f`, values converted back to host order.
void ExpectDecodesTo(const Bytes& data, const FrameDef& f) {
  FrameHeader h;
  ASSERT_EQ(DecodeExact(data, &h), DecodeError::kOk);
  EXPECT_EQ(h.version, kVersion);
  EXPECT_EQ(h.flags, f.h.flags);
  EXPECT_EQ(h.sender, f.h.sender);
  EXPECT_EQ(h.config_hash, f.h.config_hash);
  EXPECT_EQ(h.seq, f.h.seq);
  EXPECT_EQ(h.send_time_ns, f.h.send_time_ns);
  EXPECT_EQ(h.entry_count, f.entries.size());
  EXPECT_EQ(h.dest, f.h.dest);
  EntryIterator it(data.data(), h);
  EntryView v;
  for (const EntryDef& e : f.entries) {
    ASSERT_TRUE(it.Next(&v));
    EXPECT_EQ(v.signal, e.signal);
    EXPECT_EQ(v.type, e.type);
    EXPECT_EQ(v.flags, e.flags);
    EXPECT_EQ(v.count, e.count());
    EXPECT_EQ(v.value_len, e.value.size());
    EXPECT_EQ(v.seq, e.seq);
    EXPECT_EQ(v.source_time_ns, e.time);
    ASSERT_GE(v.value, data.data());
    ASSERT_LE(v.value + v.value_len, data.data() + data.size());
    EXPECT_EQ(v.offset, e.offset);
    EXPECT_EQ(v.total_len, (e.flags & kEntryFragment) ? e.whole_count * ElemSize(e.type) : e.value.size());
    Bytes host(v.value_len);
    ValueToHost(v.type, v.value, host.data(), v.value_len / ElemSize(v.type));
    EXPECT_EQ(host, e.value) << "signal " << e.signal;
  }
  EXPECT_FALSE(it.Next(&v));
}

// ---------------------------------------------------------------------------------------
// The vectors of docs/protocol.md.

struct DocVector {
  std::string expect;
  Bytes data;
};

std::string Attr(const std::string& line, const std::string& key) {
  const size_t p = line.find(key + "=");
  if (p == std::string::npos) return "";
  const size_t b = p + key.size() + 1;
  return line.substr(b, line.find_first_of(" \t", b) - b);
}

// Parses every "```hex name=N expect=E" fenced block; '#' starts a comment.
std::map<std::string, DocVector> ReadDocVectors() {
  // $CCOMM_SOURCE_DIR first: on a target (ptest) the document is installed elsewhere.
  const char* dir = getenv("CCOMM_SOURCE_DIR") ? getenv("CCOMM_SOURCE_DIR") : CCOMM_SOURCE_DIR;
  const std::string path = std::string(dir) + "/docs/protocol.md";
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::map<std::string, DocVector> out;
  std::string line, name;
  DocVector cur;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside) {
      if (line.rfind("```hex", 0) == 0) {
        inside = true;
        name = Attr(line, "name");
        cur = DocVector{Attr(line, "expect"), {}};
        EXPECT_FALSE(name.empty() || cur.expect.empty()) << "bad block header: " << line;
      }
      continue;
    }
    if (line.rfind("```", 0) == 0) {
      EXPECT_EQ(out.count(name), 0u) << "duplicate vector " << name;
      out[name] = cur;
      inside = false;
      continue;
    }
    std::string hex;
    for (char c : line.substr(0, line.find('#'))) {
      if (c == ' ' || c == '\t' || c == '\r') continue;
      EXPECT_TRUE(std::isxdigit(static_cast<unsigned char>(c))) << name << ": " << line;
      hex += c;
    }
    EXPECT_EQ(hex.size() % 2, 0u) << name << ": odd number of digits: " << line;
    for (size_t i = 0; i + 1 < hex.size(); i += 2) {
      cur.data.push_back(static_cast<uint8_t>(std::stoul(hex.substr(i, 2), nullptr, 16)));
    }
  }
  EXPECT_FALSE(inside) << "unterminated block " << name;
  return out;
}

// Contents of the valid vectors; scripts/wire_vectors.py defines the same independently.
std::map<std::string, FrameDef> ValidVectors() {
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

TEST(DocVectors, ValidVectorsMatchEncoderAndDecoder) {
  const auto doc = ReadDocVectors();
  const auto valid = ValidVectors();
  size_t ok_in_doc = 0;  // data frames and heartbeats; summary_test.cpp checks the summaries
  for (const auto& d : doc)
    ok_in_doc += d.second.expect == "ok" && !(d.second.data.size() > 5 && (d.second.data[5] & kFlagSummary));
  EXPECT_EQ(ok_in_doc, valid.size()) << "every expect=ok vector needs a definition here";
  for (const auto& v : valid) {
    SCOPED_TRACE(v.first);
    auto it = doc.find(v.first);
    ASSERT_NE(it, doc.end()) << "missing from docs/protocol.md";
    EXPECT_EQ(it->second.expect, "ok");
    EXPECT_EQ(Encode(v.second), it->second.data);
    ExpectDecodesTo(it->second.data, v.second);
  }
}

TEST(DocVectors, MalformedVectorsAreRejectedAsDocumented) {
  const auto doc = ReadDocVectors();
  size_t bad = 0;
  std::map<std::string, int> kinds;
  for (const auto& d : doc) {
    if (d.second.expect == "ok") continue;
    ++bad;
    FrameHeader h;
    h.sender = 0xBEEF;  // must stay untouched on failure
    const DecodeError e = DecodeExact(d.second.data, &h);
    EXPECT_STREQ(DecodeErrorName(e), d.second.expect.c_str()) << d.first;
    EXPECT_EQ(h.sender, 0xBEEF) << d.first;
    ++kinds[d.second.expect];
  }
  EXPECT_GE(bad, 10u);
  EXPECT_EQ(kinds.size(), 7u) << "the document should show every DecodeError";
}

// ---------------------------------------------------------------------------------------
// Round trips.

TEST(RoundTrip, EveryTypeAndCount) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<Bytes> values = {
      HostBytes<uint8_t>({1, 0, 1, 1, 0, 0, 1, 0, 1}),
      HostBytes<int32_t>({INT32_MIN, -1, 0, 1, INT32_MAX}),
      HostBytes<uint32_t>({0, 1, 0x80000000u, UINT32_MAX, 0x01020304u}),
      HostBytes<int64_t>({INT64_MIN, -1, 0, INT64_MAX, 0x0102030405060708}),
      HostBytes<float>({-0.0f, inf, -inf, std::numeric_limits<float>::denorm_min(), 1e30f}),
      HostBytes<double>({nan, -0.0, 1e-310, std::numeric_limits<double>::max(), -1.5}),
  };
  for (uint8_t type = kBool; type <= kDouble; ++type) {
    const Bytes& all = values[type - 1];
    const size_t es = ElemSize(type);
    // Every count from 1 up covers every padding length.
    for (size_t count = 1; count * es <= all.size(); ++count) {
      SCOPED_TRACE(testing::Message() << "type " << int(type) << " count " << count);
      FrameDef f{Header(0, 5, 0xFFFFFFFF, UINT64_MAX, static_cast<uint16_t>(type)), {}, {}};
      f.entries.push_back({0xFFFF, type, kEntryEvent, UINT32_MAX, UINT64_MAX,
                           Bytes(all.begin(), all.begin() + count * es)});
      f.entries.push_back({0, type, 0, 0, 0, Bytes(all.begin(), all.begin() + es)});
      const Bytes data = Encode(f);
      EXPECT_EQ(data.size() % 8, 0u);
      EXPECT_EQ(data.size(), kHeaderSize + FrameWriter::EntrySize(count * es) +
                                 FrameWriter::EntrySize(es));
      ExpectDecodesTo(data, f);
    }
  }
}

TEST(RoundTrip, BoolIsNormalisedToZeroOrOne) {
  Bytes buf(kMaxFrameSize);
  FrameWriter w(buf.data(), buf.size());
  w.Begin(Header(0, 1, 1, 1));
  const uint8_t v[3] = {0, 2, 255};
  ASSERT_TRUE(w.Add(1, kBool, 0, 3, 1, 1, v, 3));
  buf.resize(w.Finish());
  FrameHeader h;
  ASSERT_EQ(DecodeExact(buf, &h), DecodeError::kOk);
  EntryIterator it(buf.data(), h);
  EntryView e;
  ASSERT_TRUE(it.Next(&e));
  EXPECT_EQ(e.value[0], 0);
  EXPECT_EQ(e.value[1], 1);
  EXPECT_EQ(e.value[2], 1);
}

TEST(RoundTrip, HeartbeatWithTag) {
  FrameDef f{Header(kFlagHeartbeat | kFlagAuth, 9, 1, 1, 0xFFFE), {}, Bytes(kAuthTagSize, 0xAA)};
  const Bytes data = Encode(f);
  EXPECT_EQ(data.size(), kHeaderSize + kAuthTagSize);
  ExpectDecodesTo(data, f);
}

TEST(RoundTrip, WriterIsReusable) {
  Bytes buf(kMaxFrameSize);
  FrameWriter w(buf.data(), buf.size());
  for (int i = 0; i < 3; ++i) {
    w.Begin(Header(0, 1, static_cast<uint32_t>(i), 1));
    const int32_t x = i;
    ASSERT_TRUE(w.Add(1, kInt32, 0, 1, 1, 1, &x, 4));
    EXPECT_EQ(w.entries(), 1);
    EXPECT_EQ(w.Finish(), kHeaderSize + 32);
  }
}

// ---------------------------------------------------------------------------------------
// Size limits.

TEST(Limits, LargestSingleEntryFillsTheFrame) {
  const size_t max_doubles = (kMaxFrameSize - kHeaderSize - kEntryHeaderSize) / 8;  // 177
  std::vector<double> v(max_doubles + 1);
  for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<double>(i) * 0.5;
  std::unique_ptr<uint8_t[]> buf(new uint8_t[kMaxFrameSize]);
  FrameWriter w(buf.get(), kMaxFrameSize);
  w.Begin(Header(0, 1, 1, 1));
  EXPECT_FALSE(w.Add(1, kDouble, 0, static_cast<uint16_t>(max_doubles + 1), 1, 1, v.data(),
                     (max_doubles + 1) * 8));
  ASSERT_TRUE(w.Add(1, kDouble, 0, static_cast<uint16_t>(max_doubles), 1, 1, v.data(),
                    max_doubles * 8));
  ASSERT_EQ(w.Finish(), kMaxFrameSize);
  FrameHeader h;
  ASSERT_EQ(DecodeHeader(buf.get(), kMaxFrameSize, &h), DecodeError::kOk);
  EntryIterator it(buf.get(), h);
  EntryView e;
  ASSERT_TRUE(it.Next(&e));
  std::vector<double> out(e.count);
  ValueToHost(e.type, e.value, out.data(), e.count);
  EXPECT_EQ(out, std::vector<double>(v.begin(), v.begin() + max_doubles));

  // With a tag announced, the writer keeps room for it.
  w.Begin(Header(kFlagAuth, 1, 1, 1));
  EXPECT_FALSE(w.Add(1, kDouble, 0, static_cast<uint16_t>(max_doubles), 1, 1, v.data(),
                     max_doubles * 8));
  ASSERT_TRUE(w.Add(1, kDouble, 0, static_cast<uint16_t>(max_doubles - 2), 1, 1, v.data(),
                    (max_doubles - 2) * 8));
  EXPECT_EQ(w.Finish() + kAuthTagSize, kMaxFrameSize);
}

TEST(Limits, AddRefusesWhenFullAndLeavesFrameUnchanged) {
  Bytes buf(kMaxFrameSize + 64, 0xEE);  // canary bytes after kMaxFrameSize
  FrameWriter w(buf.data(), buf.size());  // capacity above the frame bound
  w.Begin(Header(0, 1, 1, 1));
  const uint8_t one = 1;
  size_t added = 0;
  while (w.Add(static_cast<uint16_t>(added), kBool, 0, 1, 1, 1, &one, 1)) ++added;
  EXPECT_EQ(added, (kMaxFrameSize - kHeaderSize) / 32);  // 45 entries of 32 bytes
  const size_t size = w.size();
  const Bytes before(buf.begin(), buf.end());
  EXPECT_FALSE(w.Add(99, kBool, 0, 1, 1, 1, &one, 1));
  EXPECT_EQ(w.size(), size);
  EXPECT_EQ(w.entries(), added);
  EXPECT_EQ(Bytes(buf.begin(), buf.end()), before);
  const size_t n = w.Finish();
  EXPECT_LE(n, kMaxFrameSize);
  for (size_t i = kMaxFrameSize; i < buf.size(); ++i) ASSERT_EQ(buf[i], 0xEE);
  buf.resize(n);
  EXPECT_EQ(Decode(buf), DecodeError::kOk);
}

TEST(Limits, SmallCapacityIsNeverExceeded) {
  // For every capacity, the writer stays inside an exactly-sized heap buffer.
  const int32_t v[3] = {1, 2, 3};
  for (size_t cap = 0; cap <= 128; ++cap) {
    std::unique_ptr<uint8_t[]> buf(new uint8_t[cap]);
    FrameWriter w(buf.get(), cap);
    w.Begin(Header(0, 1, 1, 1));
    size_t added = 0;
    while (w.Add(1, kInt32, 0, 3, 1, 1, v, sizeof v)) ++added;
    EXPECT_EQ(added, cap < kHeaderSize ? 0 : (cap - kHeaderSize) / 40) << cap;
    const size_t n = w.Finish();
    EXPECT_EQ(n, added ? kHeaderSize + 40 * added : 0) << cap;
    FrameHeader h;
    if (n) {
      EXPECT_EQ(DecodeHeader(buf.get(), n, &h), DecodeError::kOk) << cap;
    }
  }
}

TEST(Limits, AddRejectsInvalidArguments) {
  Bytes buf(kMaxFrameSize);
  FrameWriter w(buf.data(), buf.size());
  const double d[2] = {1, 2};
  EXPECT_FALSE(w.Add(1, kDouble, 0, 1, 1, 1, d, 8)) << "before Begin";
  EXPECT_EQ(w.Finish(), 0u) << "before Begin";
  w.Begin(Header(0, 1, 1, 1));
  EXPECT_FALSE(w.Add(1, 0, 0, 1, 1, 1, d, 8)) << "type 0";
  EXPECT_FALSE(w.Add(1, 7, 0, 1, 1, 1, d, 8)) << "type 7";
  EXPECT_FALSE(w.Add(1, kDouble, 0, 0, 1, 1, d, 0)) << "count 0";
  EXPECT_FALSE(w.Add(1, kDouble, 0, 2, 1, 1, d, 8)) << "len mismatch";
  EXPECT_FALSE(w.Add(1, kDouble, 0, 1, 1, 1, d, 16)) << "len mismatch";
  EXPECT_FALSE(w.Add(1, kDouble, 2, 1, 1, 1, d, 8)) << "unknown entry flag";
  EXPECT_FALSE(w.Add(1, kDouble, 0, 1, 1, 1, nullptr, 8)) << "no value";
  EXPECT_EQ(w.size(), kHeaderSize);
  EXPECT_EQ(w.Finish(), 0u) << "data frame without entries";
  EXPECT_TRUE(w.Add(1, kDouble, 0, 2, 1, 1, d, 16));
  EXPECT_GT(w.Finish(), 0u);

  w.Begin(Header(kFlagHeartbeat, 1, 1, 1));
  EXPECT_FALSE(w.Add(1, kDouble, 0, 1, 1, 1, d, 8)) << "heartbeat";
  EXPECT_EQ(w.Finish(), kHeaderSize);

  w.Begin(Header(0x04, 1, 1, 1));
  EXPECT_FALSE(w.Add(1, kDouble, 0, 1, 1, 1, d, 8)) << "unknown frame flag";
  EXPECT_EQ(w.Finish(), 0u);
}

// ---------------------------------------------------------------------------------------
// Malformed input.

class Malformed : public testing::Test {
 protected:
  // A frame with a bool[3] (5 padding bytes) and an int32[3] (4 padding bytes).
  void SetUp() override {
    FrameDef f{Header(0, 4, 10, 20), {}, {}};
    f.entries.push_back({1, kBool, 0, 1, 2, HostBytes<uint8_t>({1, 0, 1})});
    f.entries.push_back({2, kInt32, kEntryEvent, 3, 4, HostBytes<int32_t>({-7, 8, 9})});
    good_ = Encode(f);
    ASSERT_EQ(good_.size(), 32u + 32 + 40);
    ASSERT_EQ(Decode(good_), DecodeError::kOk);
  }
  DecodeError With(size_t off, uint8_t value) const {
    Bytes b = good_;
    b.at(off) = value;
    return Decode(b);
  }
  static constexpr size_t kE0 = 32, kE1 = 64;  // entry offsets
  Bytes good_;
};

TEST_F(Malformed, Header) {
  EXPECT_EQ(With(0, 0x44), DecodeError::kBadMagic);
  EXPECT_EQ(With(3, 0x57 ^ 0x80), DecodeError::kBadMagic);
  EXPECT_EQ(With(4, 0), DecodeError::kBadVersion);
  EXPECT_EQ(With(4, 2), DecodeError::kBadVersion);
  for (int bit = 2; bit < 8; ++bit) EXPECT_EQ(With(5, 1u << bit), DecodeError::kBadHeader) << bit;
  for (size_t off = 30; off < 32; ++off) EXPECT_EQ(With(off, 1), DecodeError::kBadHeader) << off;
  // dest is any node id; which ones exist is the receiver's business.
  for (uint8_t v : {0x00, 0x7F, 0xFF}) {
    EXPECT_EQ(With(28, v), DecodeError::kOk);
    EXPECT_EQ(With(29, v), DecodeError::kOk);
  }
  EXPECT_EQ(With(5, kFlagHeartbeat), DecodeError::kBadHeader) << "heartbeat with entries";
  EXPECT_EQ(With(5, kFlagAuth), DecodeError::kTooShort) << "tag announced, not present";
}

TEST_F(Malformed, Counts) {
  EXPECT_EQ(With(25, 0), DecodeError::kBadHeader) << "entry_count 0";
  EXPECT_EQ(With(25, 1), DecodeError::kBadHeader) << "entry_count 1, payload holds 2";
  EXPECT_EQ(With(25, 3), DecodeError::kBadEntry) << "entry_count 3, payload holds 2";
  EXPECT_EQ(With(24, 1), DecodeError::kBadEntry) << "entry_count 258";
  EXPECT_EQ(With(27, 72 - 8), DecodeError::kTrailingBytes) << "payload_len shorter";
  EXPECT_EQ(With(27, 72 + 8), DecodeError::kTooShort) << "payload_len longer";
  EXPECT_EQ(With(27, 72 - 4), DecodeError::kBadHeader) << "payload_len not a multiple of 8";
  EXPECT_EQ(With(26, 0x05), DecodeError::kTooShort) << "32 + 1352 bytes: allowed, absent";
  EXPECT_EQ(With(26, 0x06), DecodeError::kBadHeader) << "32 + 1608 > kMaxFrameSize";
  EXPECT_EQ(With(26, 0xFF), DecodeError::kBadHeader) << "frame above kMaxFrameSize";
}

TEST_F(Malformed, Entries) {
  for (int t : {0, 7, 8, 255}) EXPECT_EQ(With(kE0 + 2, static_cast<uint8_t>(t)), DecodeError::kBadEntry) << t;
  // bool -> int32 changes the element size: value_len no longer matches.
  EXPECT_EQ(With(kE0 + 2, kInt32), DecodeError::kBadEntry);
  // int32 <-> uint32 <-> float share a size: the frame stays valid (types are the
  // receiver's business, checked against the configuration).
  EXPECT_EQ(With(kE1 + 2, kFloat), DecodeError::kOk);
  for (int bit = 1; bit < 8; ++bit) {
    EXPECT_EQ(With(kE0 + 3, static_cast<uint8_t>(1u << bit)), DecodeError::kBadEntry) << bit;
  }
  EXPECT_EQ(With(kE0 + 5, 0), DecodeError::kBadEntry) << "count 0";
  EXPECT_EQ(With(kE0 + 5, 2), DecodeError::kBadEntry) << "count != value_len";
  EXPECT_EQ(With(kE0 + 7, 2), DecodeError::kBadEntry) << "value_len != count";
  EXPECT_EQ(With(kE1 + 7, 11), DecodeError::kBadEntry) << "value_len 11 for int32[3]";
  // Consistent count/value_len that overruns the payload.
  {
    Bytes b = good_;
    b[kE1 + 5] = 5;
    b[kE1 + 7] = 20;  // 24 + 24 bytes, 40 left
    EXPECT_EQ(Decode(b), DecodeError::kBadEntry);
  }
  for (size_t off = 12; off < 16; ++off) {
    EXPECT_EQ(With(kE0 + off, 0x80), DecodeError::kBadEntry) << off;
  }
  for (uint8_t v : {2, 3, 128, 255}) EXPECT_EQ(With(kE0 + 24 + 1, v), DecodeError::kBadEntry) << int(v);
  for (size_t off = kE0 + 24 + 3; off < kE1; ++off) EXPECT_EQ(With(off, 1), DecodeError::kBadEntry) << off;
  for (size_t off = kE1 + 24 + 12; off < kE1 + 40; ++off) {
    EXPECT_EQ(With(off, 0x10), DecodeError::kBadEntry) << off;
  }
}

// Every prefix of every valid frame is rejected, reading only inside the prefix (ASan
// checks that: the prefix is a heap allocation of exactly that size).
TEST(Bounds, EveryTruncationIsRejected) {
  for (const auto& v : ValidVectors()) {
    const Bytes full = Encode(v.second);
    for (size_t n = 0; n < full.size(); ++n) {
      EXPECT_EQ(Decode(Bytes(full.begin(), full.begin() + n)), DecodeError::kTooShort)
          << v.first << " cut to " << n;
    }
    Bytes longer = full;
    longer.push_back(0);
    EXPECT_EQ(Decode(longer), DecodeError::kTrailingBytes) << v.first;
    longer.resize(kMaxFrameSize + 100, 0);
    EXPECT_EQ(Decode(longer), DecodeError::kTrailingBytes) << v.first;
  }
}

// Any single-byte change either is rejected or yields a frame that re-encodes to the very
// same bytes: there is one encoding per frame, and nothing is silently reinterpreted.
TEST(Bounds, SingleByteMutationsAreRejectedOrCanonical) {
  size_t accepted = 0, rejected = 0;
  for (const auto& v : ValidVectors()) {
    const Bytes full = Encode(v.second);
    for (size_t off = 0; off < full.size(); ++off) {
      for (int x = 1; x < 256; ++x) {
        Bytes b = full;
        b[off] = static_cast<uint8_t>(b[off] ^ x);
        FrameHeader h;
        if (DecodeExact(b, &h) != DecodeError::kOk) {
          ++rejected;
          continue;
        }
        ++accepted;
        Bytes out(kMaxFrameSize);
        FrameWriter w(out.data(), out.size());
        w.Begin(h);
        EntryIterator it(b.data(), h);
        EntryView e;
        while (it.Next(&e)) {
          Bytes host(e.value_len);
          ValueToHost(e.type, e.value, host.data(), e.value_len / ElemSize(e.type));
          ASSERT_TRUE(AddEntry(&w, e.signal, e.type, e.flags, e.count, e.seq, e.source_time_ns, e.offset,
                               host.data(), host.size()));
        }
        const size_t n = w.Finish();
        ASSERT_EQ(n, h.payload_len + kHeaderSize);
        ASSERT_EQ(0, std::memcmp(out.data(), b.data(), n)) << v.first << " offset " << off;
      }
    }
  }
  EXPECT_GT(accepted, 0u);
  EXPECT_GT(rejected, 0u);
}

TEST(Ethernet, PaddedHeartbeatIsTrimmed) {
  const Bytes hb = Encode(ValidVectors()["heartbeat"]);
  Bytes padded = hb;
  padded.resize(kEthMinPayload, 0);
  EXPECT_EQ(Decode(padded), DecodeError::kTrailingBytes);
  EXPECT_EQ(TrimEthernetPadding(padded.data(), padded.size()), hb.size());
  padded.resize(TrimEthernetPadding(padded.data(), padded.size()));
  EXPECT_EQ(Decode(padded), DecodeError::kOk);

  Bytes dirty = hb;
  dirty.resize(kEthMinPayload, 0);
  dirty.back() = 1;  // not padding
  EXPECT_EQ(TrimEthernetPadding(dirty.data(), dirty.size()), dirty.size());

  Bytes big = hb;
  big.resize(kEthMinPayload + 2, 0);  // longer than any padding: untouched
  EXPECT_EQ(TrimEthernetPadding(big.data(), big.size()), big.size());

  const Bytes ev = Encode(ValidVectors()["event"]);
  EXPECT_EQ(TrimEthernetPadding(ev.data(), ev.size()), ev.size());
  EXPECT_EQ(TrimEthernetPadding(hb.data(), 20), 20u);
  EXPECT_EQ(TrimEthernetPadding(nullptr, 0), 0u);
}

TEST(Names, DistinctForEveryError) {
  std::map<std::string, int> seen;
  for (int e = 0; e <= static_cast<int>(DecodeError::kTrailingBytes); ++e) {
    const char* n = DecodeErrorName(static_cast<DecodeError>(e));
    ASSERT_NE(n, nullptr);
    EXPECT_EQ(seen[n]++, 0) << n;
  }
  EXPECT_STREQ(DecodeErrorName(DecodeError::kOk), "ok");
}

}  // namespace
}  // namespace wire
}  // namespace ccomm
