// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: decode arbitrary bytes as a frame, walk and convert every entry, and
// check the codec's two promises: nothing outside the input is read (ASan, the input
// buffer is exactly `size` bytes), and an accepted frame re-encodes to the same bytes
// (one encoding per frame, so no input is silently reinterpreted).
#include <cstdlib>
#include <cstring>

#include "common/value_type.h"
#include "wire/summary.h"
#include "wire/wire.h"

using namespace ccomm::wire;

namespace {

// ValueToHost writes at most kMaxFrameSize bytes for any accepted entry.
alignas(8) uint8_t g_host[kMaxFrameSize];
uint8_t g_out[kMaxFrameSize];

void Check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Raw Ethernet receivers trim padding first; exercise that path too.
  const size_t len = TrimEthernetPadding(data, size);
  Check(len <= size);
  FrameHeader h;
  const DecodeError err = DecodeHeader(data, len, &h);
  Check(DecodeErrorName(err) != nullptr);

  // DecodeFrame with a receiver's table of known entries must give the same verdict.
  // The table takes the prefixes found at every 8-byte position of the input (those
  // EntryPrefix accepts), so known entries, near misses and unknown ones all occur.
  KnownEntry known[64] = {};
  for (size_t off = kHeaderSize; off + 8 <= len; off += 8) {
    const uint8_t* p = data + off;
    const uint16_t signal = static_cast<uint16_t>((p[0] << 8) | p[1]);
    const uint16_t count = static_cast<uint16_t>((p[4] << 8) | p[5]);
    const uint16_t vlen = static_cast<uint16_t>((p[6] << 8) | p[7]);
    if (signal < 64) known[signal] = MakeKnownEntry(EntryPrefix(signal, p[2], p[3], count, vlen), p[2], vlen);
  }
  FrameHeader h2;
  Check(DecodeFrame(data, len, &h2, known, 64) == err);
  if (err != DecodeError::kOk) return 0;
  Check(h2.seq == h.seq && h2.entry_count == h.entry_count && h2.payload_len == h.payload_len);
  // The entries it calls known are the leading ones, each with its signal's known prefix
  // and size (a receiver applies those without looking again).
  Check(h2.known_entries <= h2.entry_count && h.known_entries == 0);
  {
    EntryRef ref = FirstEntry(data);
    for (uint16_t i = 0; i < h2.known_entries; ++i, ref = ref.next()) {
      Check(ref.signal() < 64 && known[ref.signal()].prefix == ref.prefix() && ref.prefix() != 0);
      Check(known[ref.signal()].size == kEntryHeaderSize + ref.value_len());
    }
  }

  const size_t tag = (h.flags & kFlagAuth) ? kAuthTagSize : 0;
  Check(len == kHeaderSize + h.payload_len + tag && len <= kMaxFrameSize);

  if (h.flags & kFlagSummary) {  // a node summary: its reader and writer round-trip too
    SummaryHead head;
    ReadSummaryHead(data, &head);
    SummaryWriter sw(g_out, sizeof g_out);
    Check(sw.Begin(h, head));
    for (uint16_t i = 0; i < head.record_count; ++i) {
      SummaryRecord r;
      ReadSummaryRecord(data, i, &r);
      Check(sw.Add(r));
    }
    const size_t out = sw.Finish();
    Check(out == len - tag);
    Check(std::memcmp(g_out, data, out) == 0);
    return 0;
  }
  FrameWriter w(g_out, sizeof g_out);
  w.Begin(h);
  EntryIterator it(data, h);
  EntryView e;
  uint16_t n = 0;
  EntryRef ref = FirstEntry(data);
  while (it.Next(&e)) {
    ++n;
    Check(ref.prefix() == e.prefix && ref.signal() == e.signal && ref.seq() == e.seq &&
          ref.value() == e.value && ref.value_len() == e.value_len && ref.source_time_ns() == e.source_time_ns);
    EntryView rv;
    ref.Read(&rv);
    Check(rv.total_len == e.total_len && rv.offset == e.offset && rv.flags == e.flags && rv.count == e.count);
    ref = ref.next();
    Check(e.value >= data && e.value + e.value_len <= data + len);
    Check(e.value_len <= sizeof g_host);
    ValueToHost(e.type, e.value, g_host, e.value_len / ccomm::ValueTypeSize(e.type));
    if (e.flags & kEntryFragment) {  // a part of a larger value: its own sub-header
      Check(e.offset + e.value_len <= e.total_len && e.value_len < e.total_len);
      Check(w.AddFragment(e.signal, e.type, static_cast<uint8_t>(e.flags & ~kEntryFragment), e.count, e.seq,
                          e.source_time_ns, e.offset, g_host, e.value_len));
    } else {
      Check(w.Add(e.signal, e.type, e.flags, e.count, e.seq, e.source_time_ns, g_host, e.value_len));
    }
  }
  Check(n == h.entry_count);
  const size_t out = w.Finish();
  Check(out == len - tag);
  Check(std::memcmp(g_out, data, out) == 0);
  return 0;
}
