// SPDX-License-Identifier: Apache-2.0
// The prepared-entry fast paths (EntryPrefix, FrameWriter::AddPrepared, EntryView::prefix)
// must give exactly the bytes and the verdicts of the checked ones (Add, DecodeHeader).
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "wire/wire.h"

namespace ccomm {
namespace wire {
namespace {

using Bytes = std::vector<uint8_t>;
constexpr uint8_t kTypes[] = {1, 2, 3, 4, 5, 6};  // bool, int32, uint32, int64, float, double
size_t ElemSize(uint8_t type) { return type == 1 ? 1 : (type == 4 || type == 6) ? 8 : 4; }

FrameHeader Header() {
  FrameHeader h;
  h.sender = 3;
  h.dest = 1;
  h.config_hash = 0x12345678;
  h.seq = 9;
  h.send_time_ns = 1234567;
  return h;
}

TEST(PreparedEntry, SameBytesAsAddForEveryTypeCountAndFlag) {
  std::mt19937_64 rng(7);
  for (uint8_t type : kTypes) {
    for (uint16_t count = 1; count <= 20; ++count) {
      for (uint8_t flags : {uint8_t{0}, uint8_t{kEntryEvent}}) {
        const size_t len = count * ElemSize(type);
        Bytes value(len);
        for (auto& b : value) b = static_cast<uint8_t>(rng());
        Bytes a(kMaxFrameSize), p(kMaxFrameSize, 0xEE);  // p: garbage where padding goes
        FrameWriter wa(a.data(), a.size()), wp(p.data(), p.size());
        wa.Begin(Header());
        wp.Begin(Header());
        const uint16_t signal = static_cast<uint16_t>(0x0102 + count);
        ASSERT_TRUE(wa.Add(signal, type, flags, count, 0xA1B2C3D4, 0x1122334455667788ull, value.data(), len));
        const uint64_t prefix = EntryPrefix(signal, type, flags, count, len);
        ASSERT_NE(prefix, 0u);
        ASSERT_TRUE(wp.AddPrepared(prefix, 0xA1B2C3D4, 0x1122334455667788ull, value.data(), len));
        const size_t na = wa.Finish(), np = wp.Finish();
        ASSERT_EQ(na, np) << "type " << int(type) << " count " << count;
        EXPECT_EQ(0, std::memcmp(a.data(), p.data(), na)) << "type " << int(type) << " count " << count;
        // The decoder hands the receiver the same prefix.
        FrameHeader h;
        ASSERT_EQ(DecodeHeader(p.data(), np, &h), DecodeError::kOk);
        EntryIterator it(p.data(), h);
        EntryView e;
        ASSERT_TRUE(it.Next(&e));
        EXPECT_EQ(e.prefix, prefix);
      }
    }
  }
}

TEST(PreparedEntry, InvalidFieldsHaveNoPrefixAndAreRefused) {
  EXPECT_EQ(EntryPrefix(1, 0, 0, 1, 8), 0u);   // unknown type
  EXPECT_EQ(EntryPrefix(1, 7, 0, 1, 8), 0u);   // unknown type
  EXPECT_EQ(EntryPrefix(1, 6, 0, 0, 0), 0u);   // count 0
  EXPECT_EQ(EntryPrefix(1, 6, 0, 2, 8), 0u);   // length != count * size
  EXPECT_EQ(EntryPrefix(1, 6, 0x80, 1, 8), 0u);  // unknown flag
  // Signal 0 of a valid type still has a non-zero prefix (0 means "none" to receivers).
  EXPECT_NE(EntryPrefix(0, 1, 0, 1, 1), 0u);
  Bytes buf(kMaxFrameSize);
  FrameWriter w(buf.data(), buf.size());
  const double v = 1.0;
  EXPECT_FALSE(w.AddPrepared(EntryPrefix(1, 6, 0, 1, 8), 1, 1, &v, 8));  // no Begin
  w.Begin(Header());
  EXPECT_FALSE(w.AddPrepared(0, 1, 1, &v, 8));
  EXPECT_FALSE(w.AddPrepared(EntryPrefix(1, 6, 0, 1, 8), 1, 1, nullptr, 8));
  FrameHeader hb = Header();
  hb.flags = kFlagHeartbeat;
  w.Begin(hb);
  EXPECT_FALSE(w.AddPrepared(EntryPrefix(1, 6, 0, 1, 8), 1, 1, &v, 8));  // heartbeats carry none
}

TEST(PreparedEntry, RefusesWhenFullAndLeavesTheFrameUnchanged) {
  Bytes buf(kMaxFrameSize);
  FrameWriter w(buf.data(), buf.size());
  w.Begin(Header());
  const double v = 2.5;
  const uint64_t prefix = EntryPrefix(4, 6, 0, 1, 8);
  size_t added = 0;
  while (w.AddPrepared(prefix, 1, 1, &v, 8)) ++added;
  EXPECT_EQ(added, (kMaxFrameSize - kHeaderSize) / FrameWriter::EntrySize(8));
  const size_t len = w.size();
  EXPECT_FALSE(w.AddPrepared(prefix, 1, 1, &v, 8));
  EXPECT_EQ(w.size(), len);
  FrameHeader h;
  EXPECT_EQ(DecodeHeader(buf.data(), w.Finish(), &h), DecodeError::kOk);
  EXPECT_EQ(h.entry_count, added);
}

}  // namespace
}  // namespace wire
}  // namespace ccomm
