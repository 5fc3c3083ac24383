// SPDX-License-Identifier: Apache-2.0
// ccomm wire format v2 codec (layout in docs/protocol.md).
//
// Every multi-byte field is read and written with memcpy plus an explicit byte swap, so
// the code has no alignment requirement and no type-punning UB on any target. Every
// access is checked against the buffer bounds before it happens.
#include "wire/wire.h"

#include "common/value_type.h"
#include "wire/summary.h"

#include <cstring>

namespace ccomm {
namespace wire {
namespace {

// Big-endian field access: one definition, wire.h's.
using be::Load;
using be::Store;

// Field offsets, see docs/protocol.md.
constexpr size_t kOffMagic = 0, kOffVersion = 4, kOffFlags = 5, kOffSender = 6, kOffHash = 8,
                 kOffSeq = 12, kOffTime = 16, kOffCount = 24, kOffPayload = 26, kOffDest = 28,
                 kOffReserved = 30;
constexpr size_t kEOffSignal = 0, kEOffType = 2, kEOffFlags = 3, kEOffCount = 4, kEOffLen = 6,
                 kEOffSeq = 8, kEOffReserved = 12, kEOffTime = 16;

constexpr uint8_t kKnownFrameFlags = kFlagHeartbeat | kFlagAuth | kFlagSummary;
constexpr uint8_t kKnownEntryFlags = kEntryEvent | kEntryFragment;
constexpr size_t kFOffTotal = kEntryHeaderSize, kFOffOffset = kEntryHeaderSize + 4;
constexpr uint8_t kTypeBool = static_cast<uint8_t>(ValueType::kBool);

inline size_t Padded(size_t n) { return (n + 7u) & ~size_t{7}; }

// Declared total length (header + payload + tag) of a header already known to be
// kHeaderSize bytes long.
inline size_t DeclaredLength(const uint8_t* buf) {
  size_t total = kHeaderSize + Load<uint16_t>(buf + kOffPayload);
  if (buf[kOffFlags] & kFlagAuth) total += kAuthTagSize;
  return total;
}

// The fragment rules of docs/protocol.md: a non-empty, element-aligned, strict part of a
// value of count x esize <= kMaxFragmentedValue bytes.
bool FragmentValid(size_t esize, size_t count, size_t part_len, size_t total, size_t offset) {
  return esize != 0 && total == count * esize && total <= kMaxFragmentedValue && part_len > 0 &&
         part_len < total && part_len % esize == 0 && offset % esize == 0 && offset < total &&
         part_len <= total - offset;
}

// A fragment entry (flags bit 1), out of the common path: the rules of CheckEntry with
// the sub-header's instead of value_len == count x size.
DecodeError CheckFragmentEntry(const uint8_t* p, size_t left, size_t esize, size_t count, size_t value_len,
                               size_t* size) {
  if ((esize == 0) | ((p[kEOffFlags] & ~kKnownEntryFlags) != 0) | (count == 0) |
      (Load<uint32_t>(p + kEOffReserved) != 0) | (left < kEntryHeaderSize + kFragmentHeaderSize))
    return DecodeError::kBadEntry;
  if (!FragmentValid(esize, count, value_len, Load<uint32_t>(p + kFOffTotal), Load<uint32_t>(p + kFOffOffset)))
    return DecodeError::kBadEntry;
  const size_t total = kEntryHeaderSize + kFragmentHeaderSize + Padded(value_len);
  if (total > left) return DecodeError::kBadEntry;
  const uint8_t* v = p + kEntryHeaderSize + kFragmentHeaderSize;
  if (esize == 1) {  // bool
    for (size_t i = 0; i < value_len; ++i) {
      if (v[i] > 1) return DecodeError::kBadEntry;
    }
  }
  for (size_t i = value_len; i < Padded(value_len); ++i) {
    if (v[i] != 0) return DecodeError::kBadEntry;
  }
  *size = total;
  return DecodeError::kOk;
}

// Checks one entry at `p` with `left` payload bytes remaining; on success stores its wire
// size in *size.
DecodeError CheckEntry(const uint8_t* p, size_t left, size_t* size) {
  if (left < kEntryHeaderSize) return DecodeError::kBadEntry;
  const uint8_t type = p[kEOffType];
  // Element sizes by type code (ValueTypeSize as a table: this runs once per entry).
  static constexpr uint8_t kElemSize[8] = {0, 1, 4, 4, 8, 4, 8, 0};
  static_assert(kElemSize[1] == ValueTypeSize(1) && kElemSize[2] == ValueTypeSize(2) &&
                    kElemSize[3] == ValueTypeSize(3) && kElemSize[4] == ValueTypeSize(4) &&
                    kElemSize[5] == ValueTypeSize(5) && kElemSize[6] == ValueTypeSize(6) &&
                    ValueTypeSize(7) == 0 && ValueTypeSize(0) == 0,
                "kElemSize is ValueTypeSize");
  const size_t esize = type < 8 ? kElemSize[type] : 0;
  const size_t count = Load<uint16_t>(p + kEOffCount);
  const size_t value_len = Load<uint16_t>(p + kEOffLen);
  if (p[kEOffFlags] & kEntryFragment) return CheckFragmentEntry(p, left, esize, count, value_len, size);
  if ((esize == 0) | ((p[kEOffFlags] & ~kKnownEntryFlags) != 0) | (count == 0) | (value_len != count * esize) |
      (Load<uint32_t>(p + kEOffReserved) != 0))
    return DecodeError::kBadEntry;
  const size_t total = kEntryHeaderSize + Padded(value_len);
  if (total > left) return DecodeError::kBadEntry;
  if (type == kTypeBool || (value_len & 7)) {  // whole 8-byte words of a 4/8-byte type: nothing more to check
    const uint8_t* v = p + kEntryHeaderSize;
    if (type == kTypeBool) {
      for (size_t i = 0; i < value_len; ++i) {
        if (v[i] > 1) return DecodeError::kBadEntry;
      }
    }
    for (size_t i = value_len; i < Padded(value_len); ++i) {
      if (v[i] != 0) return DecodeError::kBadEntry;
    }
  }
  *size = total;
  return DecodeError::kOk;
}

// Host-order elements to the wire's big-endian ones (bool: 0 or 1).
void EncodeValue(uint8_t* v, const void* value, size_t esize, size_t count) {
  const uint8_t* src = static_cast<const uint8_t*>(value);
  switch (esize) {
    case 1:  // bool: any non-zero host byte is true, the wire carries 0 or 1 only
      for (size_t i = 0; i < count; ++i) v[i] = src[i] != 0 ? 1 : 0;
      break;
    case 4:
      for (size_t i = 0; i < count; ++i) {
        uint32_t x;
        std::memcpy(&x, src + 4 * i, 4);
        Store<uint32_t>(v + 4 * i, x);
      }
      break;
    default:
      for (size_t i = 0; i < count; ++i) {
        uint64_t x;
        std::memcpy(&x, src + 8 * i, 8);
        Store<uint64_t>(v + 8 * i, x);
      }
      break;
  }
}

}  // namespace

const char* DecodeErrorName(DecodeError e) {
  switch (e) {
    case DecodeError::kOk: return "ok";
    case DecodeError::kTooShort: return "too_short";
    case DecodeError::kBadMagic: return "bad_magic";
    case DecodeError::kBadVersion: return "bad_version";
    case DecodeError::kBadHeader: return "bad_header";
    case DecodeError::kBadEntry: return "bad_entry";
    case DecodeError::kTrailingBytes: return "trailing_bytes";
    case DecodeError::kBadSummary: return "bad_summary";
  }
  return "unknown";
}

void FrameWriter::Begin(const FrameHeader& h) {
  len_ = 0;
  count_ = 0;
  limit_ = 0;
  if (buf_ == nullptr || cap_ < kHeaderSize || (h.flags & ~kKnownFrameFlags) != 0) return;
  const size_t max = kMaxFrameSize - ((h.flags & kFlagAuth) ? kAuthTagSize : 0);
  limit_ = cap_ < max ? cap_ : max;
  if (h.flags & kFlagHeartbeat) limit_ = kHeaderSize;  // heartbeats carry no entries: no room for one
  Store<uint32_t>(buf_ + kOffMagic, kMagic);
  buf_[kOffVersion] = kVersion;  // this codec writes kVersion only, whatever h.version says
  buf_[kOffFlags] = h.flags;
  Store<uint16_t>(buf_ + kOffSender, h.sender);
  Store<uint32_t>(buf_ + kOffHash, h.config_hash);
  Store<uint32_t>(buf_ + kOffSeq, h.seq);
  Store<uint64_t>(buf_ + kOffTime, h.send_time_ns);
  Store<uint16_t>(buf_ + kOffCount, 0);
  Store<uint16_t>(buf_ + kOffPayload, 0);
  Store<uint16_t>(buf_ + kOffDest, h.dest);
  Store<uint16_t>(buf_ + kOffReserved, 0);
  len_ = kHeaderSize;
}

bool FrameWriter::Add(uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, uint32_t seq,
                      uint64_t source_time_ns, const void* value, size_t value_len) {
  if (len_ < kHeaderSize) return false;                 // no successful Begin
  if (buf_[kOffFlags] & (kFlagHeartbeat | kFlagSummary)) return false;  // no entries there
  if (count_ == UINT16_MAX) return false;
  const size_t esize = ValueTypeSize(type);
  if (esize == 0 || count == 0 || value_len != size_t{count} * esize) return false;
  if ((flags & ~kEntryEvent) != 0 || value == nullptr) return false;
  // limit_ <= kMaxFrameSize, so value_len and the sizes below stay far from overflow
  // once this check passes.
  if (value_len > limit_ || EntrySize(value_len) > limit_ - len_) return false;

  uint8_t* p = buf_ + len_;
  Store<uint16_t>(p + kEOffSignal, signal);
  p[kEOffType] = type;
  p[kEOffFlags] = flags;
  Store<uint16_t>(p + kEOffCount, count);
  Store<uint16_t>(p + kEOffLen, static_cast<uint16_t>(value_len));
  Store<uint32_t>(p + kEOffSeq, seq);
  Store<uint32_t>(p + kEOffReserved, 0);
  Store<uint64_t>(p + kEOffTime, source_time_ns);

  uint8_t* v = p + kEntryHeaderSize;
  EncodeValue(v, value, esize, count);
  std::memset(v + value_len, 0, Padded(value_len) - value_len);
  len_ += EntrySize(value_len);
  ++count_;
  return true;
}

uint64_t EntryPrefix(uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, size_t value_len) {
  const size_t esize = ValueTypeSize(type);
  // Never a fragment's (those are written by AddFragment), nor a value no frame can hold.
  if (esize == 0 || count == 0 || value_len != size_t{count} * esize || (flags & ~kEntryEvent) != 0 ||
      !FrameWriter::FitsOneFrame(value_len, false))
    return 0;
  uint8_t b[8];
  Store<uint16_t>(b + kEOffSignal, signal);
  b[kEOffType] = type;
  b[kEOffFlags] = flags;
  Store<uint16_t>(b + kEOffCount, count);
  Store<uint16_t>(b + kEOffLen, static_cast<uint16_t>(value_len));
  uint64_t w;
  std::memcpy(&w, b, 8);
  return w;
}

bool FrameWriter::AddPreparedGeneric(uint64_t prefix, uint32_t seq, uint64_t source_time_ns, const void* value,
                                     size_t value_len) {
  if (len_ < kHeaderSize || (buf_[kOffFlags] & kFlagHeartbeat) || prefix == 0 || value == nullptr) return false;
  if (value_len > limit_ || EntrySize(value_len) > limit_ - len_) return false;
  uint8_t* p = buf_ + len_;
  std::memcpy(p, &prefix, 8);
  Store<uint32_t>(p + kEOffSeq, seq);
  Store<uint32_t>(p + kEOffReserved, 0);
  Store<uint64_t>(p + kEOffTime, source_time_ns);
  uint8_t* v = p + kEntryHeaderSize;
  const size_t esize = ValueTypeSize(p[kEOffType]);
  if (esize == 8 && value_len == 8) {  // the common case: one 8-byte value, no padding
    uint64_t x;
    std::memcpy(&x, value, 8);
    Store<uint64_t>(v, x);
  } else {
    EncodeValue(v, value, esize, value_len / esize);
    std::memset(v + value_len, 0, Padded(value_len) - value_len);
  }
  len_ += EntrySize(value_len);
  ++count_;
  return true;
}

bool FrameWriter::AddFragment(uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, uint32_t seq,
                              uint64_t source_time_ns, uint32_t offset, const void* part, size_t part_len) {
  if (len_ < kHeaderSize) return false;
  if (buf_[kOffFlags] & kFlagHeartbeat) return false;
  if (count_ == UINT16_MAX) return false;
  const size_t esize = ValueTypeSize(type);
  if (esize == 0 || count == 0 || (flags & ~kEntryEvent) != 0 || part == nullptr) return false;
  if (part_len > limit_ || FragmentEntrySize(part_len) > limit_ - len_) return false;
  const size_t total = size_t{count} * esize;
  if (!FragmentValid(esize, count, part_len, total, offset)) return false;

  uint8_t* p = buf_ + len_;
  Store<uint16_t>(p + kEOffSignal, signal);
  p[kEOffType] = type;
  p[kEOffFlags] = static_cast<uint8_t>(flags | kEntryFragment);
  Store<uint16_t>(p + kEOffCount, count);
  Store<uint16_t>(p + kEOffLen, static_cast<uint16_t>(part_len));
  Store<uint32_t>(p + kEOffSeq, seq);
  Store<uint32_t>(p + kEOffReserved, 0);
  Store<uint64_t>(p + kEOffTime, source_time_ns);
  Store<uint32_t>(p + kFOffTotal, static_cast<uint32_t>(total));
  Store<uint32_t>(p + kFOffOffset, offset);
  uint8_t* v = p + kEntryHeaderSize + kFragmentHeaderSize;
  EncodeValue(v, part, esize, part_len / esize);
  std::memset(v + part_len, 0, Padded(part_len) - part_len);
  len_ += FragmentEntrySize(part_len);
  ++count_;
  return true;
}

uint8_t* FrameWriter::ReserveBody(size_t n) {
  if (len_ < kHeaderSize || !(buf_[kOffFlags] & kFlagSummary) || n % 8 != 0) return nullptr;
  if (n > limit_ - len_) return nullptr;
  uint8_t* p = buf_ + len_;
  len_ += n;
  return p;
}

size_t FrameWriter::Finish() {
  if (len_ < kHeaderSize) return 0;
  const uint8_t flags = buf_[kOffFlags];
  if ((flags & kFlagSummary) && ((flags & kFlagHeartbeat) || len_ == kHeaderSize)) return 0;
  if (count_ == 0 && !(flags & (kFlagHeartbeat | kFlagSummary))) return 0;
  Store<uint16_t>(buf_ + kOffCount, count_);
  Store<uint16_t>(buf_ + kOffPayload, static_cast<uint16_t>(len_ - kHeaderSize));
  return len_;
}

DecodeError DecodeHeader(const uint8_t* buf, size_t len, FrameHeader* h) {
  return DecodeFrame(buf, len, h, nullptr, 0);
}

DecodeError DecodeFrame(const uint8_t* buf, size_t len, FrameHeader* h, const KnownEntry* known,
                        size_t known_count) {
  if (buf == nullptr || len < kHeaderSize) return DecodeError::kTooShort;
  if (Load<uint32_t>(buf + kOffMagic) != kMagic) return DecodeError::kBadMagic;
  if (buf[kOffVersion] != kVersion) return DecodeError::kBadVersion;
  const uint8_t flags = buf[kOffFlags];
  if ((flags & ~kKnownFrameFlags) != 0) return DecodeError::kBadHeader;
  if (Load<uint16_t>(buf + kOffReserved) != 0) return DecodeError::kBadHeader;
  const uint16_t entry_count = Load<uint16_t>(buf + kOffCount);
  const uint16_t payload_len = Load<uint16_t>(buf + kOffPayload);
  // One encoding per meaning: heartbeats are exactly the frames without entries; a
  // summary carries its own body instead of entries (summary.h) and is no heartbeat.
  if (flags & kFlagSummary) {
    if ((flags & kFlagHeartbeat) || entry_count != 0 || payload_len == 0) return DecodeError::kBadHeader;
  } else if (flags & kFlagHeartbeat) {
    if (entry_count != 0 || payload_len != 0) return DecodeError::kBadHeader;
  } else if (entry_count == 0 || payload_len == 0) {
    return DecodeError::kBadHeader;
  }
  if (payload_len % 8 != 0) return DecodeError::kBadHeader;  // every entry is a multiple of 8
  const size_t total = DeclaredLength(buf);
  if (total > kMaxFrameSize) return DecodeError::kBadHeader;
  if (len < total) return DecodeError::kTooShort;
  if (len > total) return DecodeError::kTrailingBytes;

  const uint8_t* p = buf + kHeaderSize;
  size_t left = payload_len;
  if (flags & kFlagSummary) {
    if (!SummaryBodyValid(p, payload_len)) return DecodeError::kBadSummary;
    left = 0;  // the body is the whole payload (entry_count is 0)
  }
  const uint8_t* const end = p + left;
  uint16_t i = 0;
  // Known entries: their first 8 bytes are ones CheckEntry accepts (EntryPrefix) with
  // whole-word values, so only the reserved word and the bounds are left to check, and
  // the size comes from the table. The first other entry ends this loop; the loop after
  // it checks the rest one by one (known ones still cheaply).
  for (; i < entry_count && end - p >= static_cast<ptrdiff_t>(kEntryHeaderSize); ++i) {
    uint64_t prefix;
    std::memcpy(&prefix, p, 8);
    const uint16_t signal = Load<uint16_t>(p + kEOffSignal);
    if (signal >= known_count) break;
    const KnownEntry& k = known[signal];
    // (A not-known signal's size never fits: that refuses an all-zero entry too.)
    if (k.prefix != prefix || static_cast<size_t>(end - p) < k.size || Load<uint32_t>(p + kEOffReserved) != 0)
      break;
    p += k.size;
  }
  const uint16_t known_entries = i;
  left = static_cast<size_t>(end - p);
  for (; i < entry_count; ++i) {
    size_t size = 0;
    if (left >= kEntryHeaderSize) {
      const uint16_t signal = Load<uint16_t>(p + kEOffSignal);
      uint64_t prefix;
      std::memcpy(&prefix, p, 8);
      if (signal < known_count && known[signal].prefix == prefix && prefix != 0 &&
          Load<uint32_t>(p + kEOffReserved) == 0 && known[signal].size <= left) {
        p += known[signal].size;
        left -= known[signal].size;
        continue;
      }
    }
    const DecodeError e = CheckEntry(p, left, &size);
    if (e != DecodeError::kOk) return e;
    p += size;
    left -= size;
  }
  if (left != 0) return DecodeError::kBadHeader;  // entries do not fill payload_len

  h->version = buf[kOffVersion];
  h->flags = flags;
  h->sender = Load<uint16_t>(buf + kOffSender);
  h->config_hash = Load<uint32_t>(buf + kOffHash);
  h->seq = Load<uint32_t>(buf + kOffSeq);
  h->send_time_ns = Load<uint64_t>(buf + kOffTime);
  h->entry_count = entry_count;
  h->payload_len = payload_len;
  h->dest = Load<uint16_t>(buf + kOffDest);
  h->known_entries = known_entries;
  return DecodeError::kOk;
}

size_t TrimEthernetPadding(const uint8_t* buf, size_t len) {
  if (buf == nullptr || len < kHeaderSize || len > kEthMinPayload) return len;
  const size_t total = DeclaredLength(buf);
  if (total >= len) return len;
  for (size_t i = total; i < len; ++i) {
    if (buf[i] != 0) return len;  // not padding: let DecodeHeader report trailing bytes
  }
  return total;
}

void ValueToHost(uint8_t type, const uint8_t* src, void* dst, size_t count) {
  uint8_t* d = static_cast<uint8_t*>(dst);
  switch (ValueTypeSize(type)) {
    case 1:
      std::memcpy(d, src, count);
      break;
    case 4:
      for (size_t i = 0; i < count; ++i) {
        const uint32_t x = Load<uint32_t>(src + 4 * i);
        std::memcpy(d + 4 * i, &x, 4);
      }
      break;
    case 8:
      for (size_t i = 0; i < count; ++i) {
        const uint64_t x = Load<uint64_t>(src + 8 * i);
        std::memcpy(d + 8 * i, &x, 8);
      }
      break;
    default:
      break;  // unknown type: nothing to convert (DecodeHeader never accepts one)
  }
}

}  // namespace wire
}  // namespace ccomm
