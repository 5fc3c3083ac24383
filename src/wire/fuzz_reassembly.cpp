// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a stream of frames fed to one Reassembler, checked against a shadow
// model. Input: type (1 byte, high bit: the signal is periodic), count (2 bytes, big-endian) of the signal, then frames,
// each as a 2-byte big-endian length and that many bytes. Every fragment entry of a
// decodable frame with the signal's type and count goes to Accept(). Promises checked:
// nothing outside a buffer is touched (ASan), a refused part changes nothing, and a value
// is reported complete only when its parts, accepted in order from offset 0 under one
// seq, cover it exactly, with the bytes those parts carried (never a mix of two values).
#include <cstdlib>
#include <cstring>
#include <vector>

#include "common/value_type.h"
#include "wire/fragment.h"

using namespace ccomm::wire;

namespace {

void Check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 3) return 0;
  const uint8_t type = static_cast<uint8_t>(data[0] % 6 + 1);
  const size_t esize = ccomm::ValueTypeSize(type);
  const size_t max_count = kMaxFragmentedValue / esize < 65535 ? kMaxFragmentedValue / esize : 65535;
  const uint16_t count = static_cast<uint16_t>(2 + ((data[1] << 8) | data[2]) % (max_count - 1));
  const uint32_t total = static_cast<uint32_t>(count * esize);
  static std::vector<uint8_t> buf, shadow, before, part;
  buf.assign(total, 0);
  shadow.assign(total, 0);
  Reassembler r;
  r.Init(buf.data(), total, (data[0] & 0x80) != 0);  // high bit: a periodic signal
  bool shadow_valid = false;  // shadow holds the accepted prefix of value shadow_seq
  uint32_t shadow_seq = 0, shadow_next = 0;

  size_t pos = 3;
  while (pos + 2 <= size) {
    const size_t len = (size_t{data[pos]} << 8) | data[pos + 1];
    pos += 2;
    if (len > size - pos) break;
    // An exact-size heap copy: ASan sees any read past the frame.
    std::vector<uint8_t> frame(data + pos, data + pos + len);
    pos += len;
    FrameHeader h;
    if (DecodeHeader(frame.data(), frame.size(), &h) != DecodeError::kOk) continue;
    EntryIterator it(frame.data(), h);
    EntryView e;
    while (it.Next(&e)) {
      if (!(e.flags & kEntryFragment) || e.type != type || e.count != count) continue;
      Check(e.total_len == total && e.offset + e.value_len <= total);
      before.assign(buf.begin(), buf.end());
      uint32_t abandoned = 99;
      const FragmentResult res = r.Accept(e, &abandoned);
      Check(abandoned <= 2);
      Check(FragmentResultName(res) != nullptr);
      if (IsRefusal(res) || res == FragmentResult::kLostValue) {
        Check(abandoned == 0);
        Check(std::memcmp(before.data(), buf.data(), total) == 0);  // refused: nothing changed
        continue;
      }
      if (res == FragmentResult::kGap) {
        Check(abandoned >= 1);
        shadow_valid = false;
        continue;
      }
      // Accepted: it must extend the shadow's prefix in order (or start a value at 0).
      if (e.offset == 0) {  // only a value's start is accepted at offset 0
        shadow_valid = true;
        shadow_seq = e.seq;
        shadow_next = 0;
      }
      Check(shadow_valid && e.seq == shadow_seq && e.offset == shadow_next);
      part.resize(e.value_len);
      ValueToHost(e.type, e.value, part.data(), e.value_len / esize);
      std::memcpy(shadow.data() + shadow_next, part.data(), e.value_len);
      shadow_next += e.value_len;
      Check(std::memcmp(buf.data(), shadow.data(), shadow_next) == 0);
      if (res == FragmentResult::kComplete) {
        Check(shadow_next == total && r.seq() == shadow_seq);
        Check(std::memcmp(r.value(), shadow.data(), total) == 0);
        shadow_valid = false;
      } else {
        Check(res == FragmentResult::kPending && shadow_next < total);
      }
    }
  }
  return 0;
}
