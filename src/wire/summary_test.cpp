// SPDX-License-Identifier: Apache-2.0
// Tests of the node summary codec: the summary vectors of docs/protocol.md (encoded by
// SummaryWriter, decoded back field by field), the writer's refusals, the size bound,
// and that no truncation or single-byte change of a valid summary is misread.
#include "wire/summary.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
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

// name -> (expect, bytes) of every ```hex block whose frame has the summary flag.
std::map<std::string, std::pair<std::string, Bytes>> SummaryVectors() {
  const char* dir = getenv("CCOMM_SOURCE_DIR") ? getenv("CCOMM_SOURCE_DIR") : CCOMM_SOURCE_DIR;
  std::ifstream in(std::string(dir) + "/docs/protocol.md");
  EXPECT_TRUE(in.good());
  std::map<std::string, std::pair<std::string, Bytes>> out;
  std::string line, name, expect;
  Bytes cur;
  bool inside = false;
  auto attr = [](const std::string& l, const std::string& k) {
    const size_t p = l.find(k + "=");
    if (p == std::string::npos) return std::string();
    const size_t b = p + k.size() + 1;
    return l.substr(b, l.find_first_of(" \t", b) - b);
  };
  while (std::getline(in, line)) {
    if (!inside) {
      if (line.rfind("```hex", 0) == 0) {
        inside = true;
        name = attr(line, "name");
        expect = attr(line, "expect");
        cur.clear();
      }
      continue;
    }
    if (line.rfind("```", 0) == 0) {
      if (cur.size() > 5 && (cur[5] & kFlagSummary)) out[name] = {expect, cur};
      inside = false;
      continue;
    }
    std::string hex;
    for (char c : line.substr(0, line.find('#')))
      if (c != ' ' && c != '\t' && c != '\r') hex += c;
    for (size_t i = 0; i + 1 < hex.size(); i += 2)
      cur.push_back(static_cast<uint8_t>(std::stoul(hex.substr(i, 2), nullptr, 16)));
  }
  return out;
}

struct SummaryDef {
  FrameHeader h;
  SummaryHead head;
  std::vector<SummaryRecord> records;
};

// A summary frame's header (wire_test_util.h's Header with the summary flag).
FrameHeader SummaryHeader(uint16_t sender, uint16_t dest, uint32_t seq, uint64_t t) {
  return Header(kFlagSummary, sender, seq, t, dest);
}

// The contents of the valid summary vectors; scripts/wire_vectors.py defines the same.
std::map<std::string, SummaryDef> ValidSummaries() {
  std::map<std::string, SummaryDef> v;
  SummaryHead a;
  a.part = 0;
  a.parts = 1;
  a.cycle_ms = 1000;
  a.uptime_ns = 5000000000;
  a.peers_alive = 0x3;
  a.frames_rx = 12000;
  a.frames_tx = 11000;
  a.frames_bad = 1;
  a.frames_lost = 2;
  a.socket_drops = 0;
  a.clock_state = 2;  // synced
  a.clock_error_ns = 12500;
  a.clock_offset_ns = 1764000000123456789;
  v["summary"] = {SummaryHeader(2, 0, 3, 6000000000), a,
                  {{1, kRoleProduced, 0, 1000000, 0, 1}, {4, kRoleConsumed, kRecordStale, 0, 3, 250}}};
  SummaryHead b;
  b.part = 1;
  b.parts = 2;
  b.cycle_ms = 400;
  b.uptime_ns = 9000000000;
  v["summary-empty-part"] = {SummaryHeader(5, kDestAll, 0, 7000000000), b, {}};
  return v;
}

Bytes Encode(const SummaryDef& d) {
  Bytes buf(kMaxFrameSize);
  SummaryWriter w(buf.data(), buf.size());
  EXPECT_TRUE(w.Begin(d.h, d.head));
  for (const SummaryRecord& r : d.records) EXPECT_TRUE(w.Add(r));
  buf.resize(w.Finish());
  return buf;
}

TEST(SummaryVectors, MatchEncoderAndDecoder) {
  const auto doc = SummaryVectors();
  const auto valid = ValidSummaries();
  size_t ok = 0, bad = 0;
  for (const auto& d : doc) (d.second.first == "ok" ? ok : bad) += 1;
  EXPECT_EQ(ok, valid.size()) << "every expect=ok summary vector needs a definition here";
  EXPECT_GE(bad, 7u);
  for (const auto& v : valid) {
    SCOPED_TRACE(v.first);
    auto it = doc.find(v.first);
    ASSERT_NE(it, doc.end());
    EXPECT_EQ(Encode(v.second), it->second.second);
    FrameHeader h;
    ASSERT_EQ(DecodeExact(it->second.second, &h), DecodeError::kOk);
    EXPECT_EQ(h.flags, kFlagSummary);
    EXPECT_EQ(h.entry_count, 0);
    EXPECT_EQ(h.sender, v.second.h.sender);
    EXPECT_EQ(h.dest, v.second.h.dest);
    SummaryHead head;
    ReadSummaryHead(it->second.second.data(), &head);
    EXPECT_EQ(head.part, v.second.head.part);
    EXPECT_EQ(head.parts, v.second.head.parts);
    EXPECT_EQ(head.record_count, v.second.records.size());
    EXPECT_EQ(head.cycle_ms, v.second.head.cycle_ms);
    EXPECT_EQ(head.uptime_ns, v.second.head.uptime_ns);
    EXPECT_EQ(head.peers_alive, v.second.head.peers_alive);
    EXPECT_EQ(head.frames_rx, v.second.head.frames_rx);
    EXPECT_EQ(head.frames_tx, v.second.head.frames_tx);
    EXPECT_EQ(head.frames_bad, v.second.head.frames_bad);
    EXPECT_EQ(head.frames_lost, v.second.head.frames_lost);
    EXPECT_EQ(head.socket_drops, v.second.head.socket_drops);
    EXPECT_EQ(head.clock_state, v.second.head.clock_state);
    EXPECT_EQ(head.clock_error_ns, v.second.head.clock_error_ns);
    EXPECT_EQ(head.clock_offset_ns, v.second.head.clock_offset_ns);
    for (uint16_t i = 0; i < head.record_count; ++i) {
      SummaryRecord r;
      ReadSummaryRecord(it->second.second.data(), i, &r);
      const SummaryRecord& e = v.second.records[i];
      EXPECT_EQ(r.signal, e.signal);
      EXPECT_EQ(r.role, e.role);
      EXPECT_EQ(r.flags, e.flags);
      EXPECT_EQ(r.rate_mhz, e.rate_mhz);
      EXPECT_EQ(r.lost, e.lost);
      EXPECT_EQ(r.age_ms, e.age_ms);
    }
  }
  for (const auto& d : doc) {
    if (d.second.first == "ok") continue;
    FrameHeader h;
    h.sender = 0xBEEF;
    EXPECT_STREQ(DecodeErrorName(DecodeExact(d.second.second, &h)), d.second.first.c_str()) << d.first;
    EXPECT_EQ(h.sender, 0xBEEF) << d.first;
  }
}

TEST(SummaryWriter, RefusesWhatTheDecoderWouldRefuse) {
  uint8_t buf[kMaxFrameSize];
  SummaryWriter w(buf, sizeof buf);
  SummaryHead head;
  FrameHeader data = SummaryHeader(1, 0, 0, 1);
  data.flags = 0;
  EXPECT_FALSE(w.Begin(data, head)) << "not a summary frame";
  EXPECT_EQ(w.Finish(), 0u);
  head.part = 1;
  head.parts = 1;
  EXPECT_FALSE(w.Begin(SummaryHeader(1, 0, 0, 1), head)) << "part out of range";
  head.part = 0;
  ASSERT_TRUE(w.Begin(SummaryHeader(1, 0, 0, 1), head));
  EXPECT_TRUE(w.Add({5, kRoleProduced, 0, 0, 0, 0}));
  EXPECT_FALSE(w.Add({5, kRoleConsumed, 0, 0, 0, 0})) << "signal ids must increase";
  EXPECT_FALSE(w.Add({3, kRoleConsumed, 0, 0, 0, 0})) << "signal ids must increase";
  EXPECT_FALSE(w.Add({6, 3, 0, 0, 0, 0})) << "unknown role";
  EXPECT_FALSE(w.Add({6, kRoleProduced, 0x04, 0, 0, 0})) << "unknown record flag";
  EXPECT_EQ(w.records(), 1u);
  FrameHeader h;
  const size_t n = w.Finish();
  ASSERT_EQ(n, kHeaderSize + kSummaryHeadSize + kSummaryRecordSize);
  EXPECT_EQ(DecodeHeader(buf, n, &h), DecodeError::kOk);
  // A summary frame takes no data entries.
  FrameWriter fw(buf, sizeof buf);
  fw.Begin(SummaryHeader(1, 0, 0, 1));
  const double v = 1;
  EXPECT_FALSE(fw.Add(1, 6, 0, 1, 1, 1, &v, sizeof v));
  EXPECT_EQ(fw.Finish(), 0u) << "a summary without a body is not a frame";
}

TEST(SummaryWriter, FullPartFitsWithAuthTag) {
  uint8_t buf[kMaxFrameSize];
  SummaryWriter w(buf, sizeof buf);
  FrameHeader fh = SummaryHeader(1, 0, 0, 1);
  fh.flags |= kFlagAuth;
  ASSERT_TRUE(w.Begin(fh, SummaryHead()));
  for (uint16_t i = 0; i < kSummaryMaxRecords; ++i) ASSERT_TRUE(w.Add({i, kRoleConsumed, kRecordNever, 0, 0, kSummaryNoAge}));
  EXPECT_FALSE(w.Add({1000, kRoleConsumed, 0, 0, 0, 0})) << "a 57th record";
  const size_t n = w.Finish();
  ASSERT_GT(n, 0u);
  EXPECT_LE(n + kAuthTagSize, kMaxFrameSize);
  FrameHeader h;
  EXPECT_EQ(DecodeHeader(buf, n + kAuthTagSize, &h), DecodeError::kOk);
}

TEST(SummaryDecode, NoTruncationOrByteFlipIsMisread) {
  const auto valid = ValidSummaries();
  const Bytes frame = Encode(valid.at("summary"));
  for (size_t len = 0; len < frame.size(); ++len) {
    FrameHeader h;
    EXPECT_NE(DecodeExact(Bytes(frame.begin(), frame.begin() + static_cast<long>(len)), &h), DecodeError::kOk) << len;
  }
  // Changing any byte of the body's structural fields (part, parts, count, role, flags,
  // reserved) must be refused or decode to exactly that change.
  size_t refused = 0;
  for (size_t i = kHeaderSize; i < frame.size(); ++i) {
    Bytes b = frame;
    b[i] ^= 0x80;
    FrameHeader h;
    if (DecodeExact(b, &h) != DecodeError::kOk) {
      ++refused;
      continue;
    }
    uint8_t out[kMaxFrameSize];
    SummaryHead head;
    ReadSummaryHead(b.data(), &head);
    SummaryWriter w(out, sizeof out);
    ASSERT_TRUE(w.Begin(h, head));
    for (uint16_t k = 0; k < head.record_count; ++k) {
      SummaryRecord r;
      ReadSummaryRecord(b.data(), k, &r);
      ASSERT_TRUE(w.Add(r));
    }
    ASSERT_EQ(w.Finish(), b.size());
    EXPECT_EQ(0, std::memcmp(out, b.data(), b.size())) << "byte " << i << " re-encodes differently";
  }
  EXPECT_GE(refused, 8u);  // part, parts, count (2), roles (2), flags (2), reserved ...
}

}  // namespace
}  // namespace wire
}  // namespace ccomm
