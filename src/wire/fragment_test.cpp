// SPDX-License-Identifier: Apache-2.0
// Tests of large-value fragmentation: FrameWriter::AddFragment + DecodeHeader round trips
// of a 64 KiB value split as ccommd splits it, and the Reassembler's state machine on every
// kind of bad or unlucky input (out of order, duplicated, overlapping, oversized,
// inconsistent, lost parts): refused or counted, and a value reported only when whole.
#include "wire/fragment.h"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace ccomm {
namespace wire {
namespace {

constexpr uint8_t kUint32 = 3;
constexpr uint32_t kElems = 16384;  // uint32[16384] = 64 KiB
constexpr uint32_t kBytes = kElems * 4;

using Frame = std::vector<uint8_t>;

// The frames ccommd sends for value `seq` whose elements all equal `fill`.
std::vector<Frame> Split(uint32_t seq, uint32_t fill, bool auth = false, uint64_t time = 1000) {
  std::vector<uint32_t> v(kElems, fill);
  std::vector<Frame> out;
  const size_t part = FrameWriter::MaxFragmentPart(auth);
  for (size_t off = 0; off < kBytes; off += part) {
    const size_t n = std::min(part, kBytes - off);
    Frame f(kMaxFrameSize);
    FrameWriter w(f.data(), f.size());
    FrameHeader h;
    h.flags = auth ? kFlagAuth : 0;
    h.seq = static_cast<uint32_t>(out.size());
    w.Begin(h);
    EXPECT_TRUE(w.AddFragment(7, kUint32, 0, static_cast<uint16_t>(kElems), seq, time, static_cast<uint32_t>(off),
                              reinterpret_cast<const uint8_t*>(v.data()) + off, n));
    const size_t len = w.Finish();
    EXPECT_GT(len, 0u);
    f.resize(len);
    if (auth) f.resize(len + kAuthTagSize, 0);
    EXPECT_LE(f.size(), kMaxFrameSize);
    out.push_back(f);
  }
  return out;
}

EntryView View(const Frame& f) {
  FrameHeader h;
  EXPECT_EQ(DecodeHeader(f.data(), f.size(), &h), DecodeError::kOk);
  EntryIterator it(f.data(), h);
  EntryView e;
  EXPECT_TRUE(it.Next(&e));
  return e;
}

struct Rx {
  std::vector<uint8_t> buf = std::vector<uint8_t>(kBytes);
  Reassembler r;
  uint32_t abandoned = 0, completed = 0, refused = 0;
  Rx() { r.Init(buf.data(), kBytes); }
  FragmentResult Feed(const Frame& f) { return Feed(View(f)); }
  FragmentResult Feed(const EntryView& e) {
    uint32_t a = 0;
    const FragmentResult res = r.Accept(e, &a);
    abandoned += a;
    if (res == FragmentResult::kComplete) {
      ++completed;
      // Whole: every element is the same (the value's fill), never a mix.
      uint32_t first;
      std::memcpy(&first, r.value(), 4);
      for (uint32_t i = 0; i < kElems; ++i) {
        uint32_t x;
        std::memcpy(&x, r.value() + 4 * i, 4);
        EXPECT_EQ(x, first) << "torn value at element " << i;
      }
    }
    if (IsRefusal(res)) ++refused;
    return res;
  }
  uint32_t Fill() const {
    uint32_t x;
    std::memcpy(&x, r.value(), 4);
    return x;
  }
};

TEST(Fragment, SplitSizes) {
  EXPECT_EQ(FrameWriter::MaxFragmentPart(false), 1408u);
  EXPECT_EQ(FrameWriter::MaxFragmentPart(true), 1392u);
  EXPECT_EQ(Split(1, 5).size(), 47u);             // ceil(65536 / 1408)
  EXPECT_EQ(Split(1, 5, true).size(), 48u);       // ceil(65536 / 1392)
  EXPECT_TRUE(FrameWriter::FitsOneFrame(1024, true));
  EXPECT_TRUE(FrameWriter::FitsOneFrame(1416, false));   // 32 + 24 + 1416 = 1472
  EXPECT_FALSE(FrameWriter::FitsOneFrame(1417, false));
  EXPECT_FALSE(FrameWriter::FitsOneFrame(1401, true));
}

TEST(Fragment, AddFragmentRefusesInvalidParts) {
  Frame f(kMaxFrameSize);
  FrameWriter w(f.data(), f.size());
  FrameHeader h;
  w.Begin(h);
  uint32_t v[4] = {1, 2, 3, 4};
  EXPECT_FALSE(w.AddFragment(1, kUint32, 0, 4, 1, 1, 0, v, 16)) << "the whole value";
  EXPECT_FALSE(w.AddFragment(1, kUint32, 0, 4, 1, 1, 2, v, 4)) << "misaligned offset";
  EXPECT_FALSE(w.AddFragment(1, kUint32, 0, 4, 1, 1, 0, v, 6)) << "misaligned length";
  EXPECT_FALSE(w.AddFragment(1, kUint32, 0, 4, 1, 1, 12, v, 8)) << "past the end";
  EXPECT_FALSE(w.AddFragment(1, kUint32, 0, 4, 1, 1, 0, v, 0)) << "empty";
  EXPECT_FALSE(w.AddFragment(1, kUint32, kEntryFragment, 4, 1, 1, 0, v, 8)) << "flag given twice";
  EXPECT_FALSE(w.AddFragment(1, 6, 0, 8193, 1, 1, 0, v, 8)) << "total above 64 KiB";
  EXPECT_FALSE(w.Add(1, kUint32, kEntryFragment, 2, 1, 1, v, 8)) << "Add never writes a fragment";
  EXPECT_TRUE(w.AddFragment(1, kUint32, kEntryEvent, 4, 1, 1, 8, v, 8));
  EXPECT_EQ(w.size(), kHeaderSize + FrameWriter::FragmentEntrySize(8));
}

TEST(Fragment, InOrderValuesComplete) {
  Rx rx;
  for (uint32_t seq = 1; seq <= 3; ++seq) {
    const auto frames = Split(seq, seq * 11);
    for (size_t i = 0; i < frames.size(); ++i) {
      const FragmentResult r = rx.Feed(frames[i]);
      EXPECT_EQ(r, i + 1 == frames.size() ? FragmentResult::kComplete : FragmentResult::kPending);
    }
    EXPECT_EQ(rx.Fill(), seq * 11);
    EXPECT_EQ(rx.r.seq(), seq);
  }
  EXPECT_EQ(rx.completed, 3u);
  EXPECT_EQ(rx.abandoned + rx.refused, 0u);
}

TEST(Fragment, LostPartLosesExactlyThatValue) {
  Rx rx;
  auto a = Split(1, 1), b = Split(2, 2), c = Split(3, 3);
  for (auto& f : a) rx.Feed(f);
  for (size_t i = 0; i < b.size(); ++i)
    if (i != 20) rx.Feed(b[i]);  // part 20 lost: the value is abandoned at part 21
  EXPECT_EQ(rx.abandoned, 1u);
  for (auto& f : c) rx.Feed(f);
  EXPECT_EQ(rx.completed, 2u);
  EXPECT_EQ(rx.Fill(), 3u);
  EXPECT_EQ(rx.abandoned, 1u) << "one lost value counted once";
  EXPECT_EQ(rx.refused, 0u) << "losses are not bad input";
}

TEST(Fragment, LostLastPartIsAbandonedByTheNextValue) {
  Rx rx;
  auto a = Split(1, 1), b = Split(2, 2);
  a.pop_back();
  for (auto& f : a) rx.Feed(f);
  EXPECT_EQ(rx.completed, 0u);
  EXPECT_TRUE(rx.r.assembling());
  for (auto& f : b) rx.Feed(f);
  EXPECT_EQ(rx.abandoned, 1u);
  EXPECT_EQ(rx.completed, 1u);
  EXPECT_EQ(rx.Fill(), 2u);
}

TEST(Fragment, LostFirstPartAndLostMiddleOfNextValueCountTwo) {
  Rx rx;
  auto a = Split(1, 1), b = Split(2, 2), c = Split(3, 3);
  for (size_t i = 0; i + 1 < a.size(); ++i) rx.Feed(a[i]);  // a: last part lost
  for (size_t i = 1; i < b.size(); ++i) rx.Feed(b[i]);      // b: first part lost
  EXPECT_EQ(rx.abandoned, 2u) << "a (in progress) and b (no first part) in one step";
  for (auto& f : c) rx.Feed(f);
  EXPECT_EQ(rx.completed, 1u);
  EXPECT_EQ(rx.abandoned, 2u);
}

TEST(Fragment, OutOfOrderPartsAbandonTheValue) {
  Rx rx;
  auto a = Split(1, 1);
  std::swap(a[3], a[4]);
  for (auto& f : a) rx.Feed(f);
  EXPECT_EQ(rx.completed, 0u) << "never reported: parts must arrive in order";
  EXPECT_EQ(rx.abandoned, 1u);
}

TEST(Fragment, DuplicatesAndOverlapsAreRefusedAndChangeNothing) {
  Rx rx;
  auto a = Split(1, 1);
  for (size_t i = 0; i < 10; ++i) rx.Feed(a[i]);
  EXPECT_EQ(rx.Feed(a[9]), FragmentResult::kDuplicate);
  EXPECT_EQ(rx.Feed(a[0]), FragmentResult::kDuplicate);
  // Overlap: a part starting inside the received bytes and reaching past them.
  EntryView e = View(a[10]);
  e.offset -= 8;
  EXPECT_EQ(rx.Feed(e), FragmentResult::kOverlap);
  for (size_t i = 10; i < a.size(); ++i) rx.Feed(a[i]);
  EXPECT_EQ(rx.completed, 1u);
  EXPECT_EQ(rx.refused, 3u);
  EXPECT_EQ(rx.abandoned, 0u);
  // The whole value again, after it completed: every part is a duplicate.
  for (auto& f : a) EXPECT_EQ(rx.Feed(f), FragmentResult::kDuplicate);
  EXPECT_EQ(rx.completed, 1u);
}

TEST(Fragment, StaleInconsistentAndOversizedAreRefused) {
  Rx rx;
  auto a = Split(5, 5), old = Split(4, 4);
  for (size_t i = 0; i < 10; ++i) rx.Feed(a[i]);
  EXPECT_EQ(rx.Feed(old[0]), FragmentResult::kStale);
  EXPECT_EQ(rx.Feed(old[10]), FragmentResult::kStale);
  EntryView e = View(a[10]);
  e.source_time_ns += 1;
  EXPECT_EQ(rx.Feed(e), FragmentResult::kInconsistent);
  e = View(a[10]);
  e.flags |= kEntryEvent;
  EXPECT_EQ(rx.Feed(e), FragmentResult::kInconsistent);
  e = View(a[10]);
  e.total_len = kBytes + 8;
  EXPECT_EQ(rx.Feed(e), FragmentResult::kOversized);
  e = View(a[10]);
  e.flags = 0;
  EXPECT_EQ(rx.Feed(e), FragmentResult::kNotFragment);
  for (size_t i = 10; i < a.size(); ++i) rx.Feed(a[i]);
  EXPECT_EQ(rx.completed, 1u);
  EXPECT_EQ(rx.Fill(), 5u);
  EXPECT_EQ(rx.refused, 6u);
  EXPECT_EQ(rx.abandoned, 0u);
}

TEST(Fragment, RestartedProducerStartsOver) {
  Rx rx;
  auto a = Split(50000, 1);
  for (auto& f : a) rx.Feed(f);
  auto b = Split(1, 2);  // far behind: a restarted producer, not a late part
  for (auto& f : b) rx.Feed(f);
  EXPECT_EQ(rx.completed, 2u);
  EXPECT_EQ(rx.Fill(), 2u);
  // Close behind: refused as stale, unless the daemon resets the reassembler (it does
  // when rule 5 sees the sender restart).
  auto c = Split(0xFFFFFFF0u, 3);
  rx.Feed(c[0]);
  rx.r.Reset();
  for (auto& f : c) rx.Feed(f);
  EXPECT_EQ(rx.completed, 3u);
}

TEST(Fragment, PeriodicResendsAreNotDuplicates) {
  Rx rx;
  rx.r.Init(rx.buf.data(), kBytes, /*resent=*/true);
  auto a = Split(1, 1);
  for (auto& f : a) rx.Feed(f);
  for (auto& f : a) rx.Feed(f);  // the next period: the same value again
  EXPECT_EQ(rx.completed, 2u);
  EXPECT_EQ(rx.refused, 0u);
  // A re-send that loses its tail, then the next re-send: it completes, nothing counted
  // lost (the value itself did arrive).
  for (size_t i = 0; i < 30; ++i) rx.Feed(a[i]);
  for (auto& f : a) rx.Feed(f);
  EXPECT_EQ(rx.completed, 3u);
  EXPECT_EQ(rx.abandoned, 0u);
  // Still refused: a middle part again, and an older value.
  for (size_t i = 0; i < 5; ++i) rx.Feed(a[i]);
  EXPECT_EQ(rx.Feed(a[2]), FragmentResult::kDuplicate);
  for (size_t i = 5; i < a.size(); ++i) rx.Feed(a[i]);
  auto b = Split(2, 2);
  for (auto& f : b) rx.Feed(f);
  EXPECT_EQ(rx.Feed(a[0]), FragmentResult::kStale);
  EXPECT_EQ(rx.Fill(), 2u);
  EXPECT_EQ(rx.completed, 5u);
}

TEST(Fragment, SequenceWrapsAround) {
  Rx rx;
  for (uint32_t seq : {0xFFFFFFFEu, 0xFFFFFFFFu, 0u, 1u}) {
    for (auto& f : Split(seq, seq)) rx.Feed(f);
  }
  EXPECT_EQ(rx.completed, 4u);
  EXPECT_EQ(rx.Fill(), 1u);
}

TEST(Fragment, DecoderRefusesBadFragmentHeaders) {
  auto a = Split(1, 1);
  FrameHeader h;
  Frame f = a[0];
  f[kHeaderSize + kEntryHeaderSize + 3] ^= 4;  // total_len 65536 -> 65540
  EXPECT_EQ(DecodeHeader(f.data(), f.size(), &h), DecodeError::kBadEntry);
  f = a[46];
  f[kHeaderSize + kEntryHeaderSize + 7] ^= 0x80;  // offset moved: part runs past the total
  EXPECT_EQ(DecodeHeader(f.data(), f.size(), &h), DecodeError::kBadEntry);
}

TEST(Fragment, NamesAreDistinct) {
  std::vector<std::string> seen;
  for (int i = 0; i <= static_cast<int>(FragmentResult::kNotFragment); ++i) {
    const std::string n = FragmentResultName(static_cast<FragmentResult>(i));
    EXPECT_NE(n, "unknown");
    for (const auto& s : seen) EXPECT_NE(s, n);
    seen.push_back(n);
  }
}

}  // namespace
}  // namespace wire
}  // namespace ccomm
