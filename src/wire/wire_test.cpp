// SPDX-License-Identifier: Apache-2.0
// Tests of wire encode/decode: the docs/protocol.md hex vectors, round trips, FrameWriter limits.
#include "wire/wire.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "wire/wire_test_util.h"

#ifndef CCOMM_SOURCE_DIR
#error "CCOMM_SOURCE_DIR must point at the source tree (set by src/wire/CMakeLists.txt)"
#endif

namespace ccomm {
namespace wire {
namespace {

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

// The contents of the expect=ok vectors, ValidVectors(), are in wire_test_util.h.

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

}  // namespace
}  // namespace wire
}  // namespace ccomm

// Copies of the wire version outside the C++ codec (tools and tests that build or dissect
// frames on their own) must follow kVersion: a stale copy would make its test send
// frames every receiver refuses as bad_version, or the dissector flag every frame.
TEST(WireVersion, EveryCopyFollowsKVersion) {
  const std::string v = std::to_string(unsigned{ccomm::wire::kVersion});
  const std::pair<const char*, std::string> copies[] = {
      {"scripts/wire_vectors.py", "\nVERSION = " + v + "\n"},
      {"integrations/wireshark/ccomm.lua", "local MAGIC, VERSION = 0x43434D57, " + v + "  -- wire: kMagic, kVersion\n"},
      {"tests/reliability/authframe.py", "MAGIC, VERSION, FLAG_HEARTBEAT, FLAG_AUTH = 0x43434D57, " + v + ","},
      {"tests/reliability/flood.c", "f[4] = " + v + "; /* wire::kVersion"},
      {"docs/protocol.md", "# ccomm wire protocol, version " + v + "\n"},
  };
  for (const auto& c : copies) {
    std::ifstream in(std::string(CCOMM_SOURCE_DIR) + "/" + c.first, std::ios::binary);
    ASSERT_TRUE(in.good()) << c.first;
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(c.second), std::string::npos) << c.first << " does not say wire version " << v;
  }
}
