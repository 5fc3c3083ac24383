// SPDX-License-Identifier: Apache-2.0
// Tests of refused frames: corrupted fields, every truncation, byte mutations, Ethernet padding.
#include "wire/wire.h"

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "wire/wire_test_util.h"

namespace ccomm {
namespace wire {
namespace {

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
  EXPECT_EQ(With(4, 1), DecodeError::kBadVersion);  // version 1: before the clock in summaries
  EXPECT_EQ(With(4, 3), DecodeError::kBadVersion);
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
