// SPDX-License-Identifier: Apache-2.0
// ccomm wire format v2: fixed-width, network byte order. Specified in docs/protocol.md;
// the hex test vectors there are the ones wire_test.cpp checks.
//
// Encoding and decoding work on caller-provided buffers, never allocate and never read
// or write outside [buf, buf + len): they are safe on the daemon's real-time paths and
// on any bytes from the wire.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "common/value_type.h"

namespace ccomm {
namespace wire {

constexpr uint32_t kMagic = 0x43434D57;  // "CCMW"
constexpr uint8_t kVersion = 2;  // 2: the node summary's head carries the sender's clock (summary.h)
constexpr size_t kHeaderSize = 32;
constexpr size_t kEntryHeaderSize = 24;
constexpr size_t kAuthTagSize = 16;
constexpr size_t kMaxFrameSize = 1472;  // fits a UDP datagram in a 1500-byte MTU; raw frames use the same bound

enum FrameFlags : uint8_t {
  kFlagHeartbeat = 1u << 0,  // frame carries no entries, only liveness
  kFlagAuth = 1u << 1,       // a kAuthTagSize-byte tag follows the entries
  kFlagSummary = 1u << 2,    // payload is a node summary (summary.h), not entries
};

enum EntryFlags : uint8_t {
  kEntryEvent = 1u << 0,     // entry is an event (queued), not a state (last value wins)
  kEntryFragment = 1u << 1,  // entry carries one part of a value too large for a frame
};

/// A fragment entry's sub-header (after the 24-byte entry header): the whole value's
/// byte length (32 bits) and this part's byte offset in it (32 bits). See fragment.h.
constexpr size_t kFragmentHeaderSize = 8;
/// Largest value a fragment entry may belong to (the codec refuses a larger total).
constexpr size_t kMaxFragmentedValue = 65536;
/// Bytes before an entry's value (or part): 24, or 32 for a fragment entry.
inline size_t EntryValueOffset(const uint8_t* entry) {
  return kEntryHeaderSize + ((entry[3] & kEntryFragment) ? kFragmentHeaderSize : 0);
}

struct FrameHeader {
  uint8_t version = kVersion;
  uint8_t flags = 0;
  uint16_t sender = 0;        // node id of the sender (position in signals.xml)
  uint32_t config_hash = 0;   // SystemConfig::hash of the sender's configuration
  uint32_t seq = 0;           // per sender and destination, +1 per frame
  uint64_t send_time_ns = 0;  // sender's CLOCK_MONOTONIC at send
  uint16_t entry_count = 0;
  uint16_t payload_len = 0;   // bytes of entries after the header (excludes the tag)
  uint16_t dest = 0;          // destination node id (offset 28), kDestAll = every node
  // Not on the wire: how many leading entries DecodeFrame matched with its known table
  // (each one's prefix is known[signal].prefix, checked with its reserved word and bounds).
  uint16_t known_entries = 0;
};
constexpr uint16_t kDestAll = 0xFFFF;

/// One decoded entry. `value` points into the frame buffer (no copy); the bytes are
/// in network byte order and are converted by ValueToHost().
struct EntryView {
  uint16_t signal = 0;
  uint8_t type = 0;
  uint8_t flags = 0;
  uint16_t count = 0;
  uint16_t value_len = 0;
  uint32_t seq = 0;
  uint64_t source_time_ns = 0;  // producer's CLOCK_MONOTONIC when the value was written
  const uint8_t* value = nullptr;  // value_len bytes (for a fragment: this part only)
  uint64_t prefix = 0;  // the entry's first 8 bytes as they lie in the frame (EntryPrefix)
  // Fragment entries (flags & kEntryFragment) only; otherwise total_len == value_len, offset 0.
  uint32_t total_len = 0;       // bytes of the whole value (count x element size)
  uint32_t offset = 0;          // byte offset of this part in the whole value
};

/// The first 8 bytes of an entry (signal, type, flags, count, value length) as they lie in
/// a frame, read as one native word: a receiver compares an entry's with the one it
/// expects for that signal in one go, a sender copies it. 0 if the fields are not a valid
/// entry (unknown type or flag, the fragment flag, count 0, value_len != count * element
/// size, a value too large for one frame); a decoded entry's prefix is never 0.
uint64_t EntryPrefix(uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, size_t value_len);

enum class DecodeError : uint8_t {
  kOk = 0,
  kTooShort,      // fewer bytes than a header, or than payload_len says
  kBadMagic,
  kBadVersion,
  kBadHeader,     // reserved bits set, or inconsistent flags / counts
  kBadEntry,      // entry runs past payload, unknown type, count/len mismatch, non-zero padding
  kTrailingBytes, // bytes after the declared payload (and tag)
  kBadSummary,    // summary frame whose body breaks a rule of summary.h
};
const char* DecodeErrorName(DecodeError e);

/// Big-endian loads and stores: every encoder and decoder of the wire module uses these.
namespace be {
template <typename T>
inline T Swap(T v) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  return v;
#else
  if constexpr (sizeof(T) == 2) return static_cast<T>(__builtin_bswap16(v));
  else if constexpr (sizeof(T) == 4) return static_cast<T>(__builtin_bswap32(v));
  else return static_cast<T>(__builtin_bswap64(v));
#endif
}
template <typename T>
inline void Store(uint8_t* p, T v) {
  v = Swap(v);
  std::memcpy(p, &v, sizeof v);
}
template <typename T>
inline T Load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return Swap(v);
}
}  // namespace be

static_assert(ValueTypeSize(4) == 8 && ValueTypeSize(6) == 8 && ValueTypeSize(1) != 8 && ValueTypeSize(2) != 8 &&
                  ValueTypeSize(3) != 8 && ValueTypeSize(5) != 8 && ValueTypeSize(7) != 8,
              "FrameWriter::AddPrepared: 0x50 is the set of 8-byte types");

/// Builds a frame in `buf` (capacity `cap`): call Begin, Add per entry, Finish.
class FrameWriter {
 public:
  FrameWriter(uint8_t* buf, size_t cap) : buf_(buf), cap_(cap) {}
  void Begin(const FrameHeader& h);
  /// Appends an entry; `value` holds count elements in host byte order (bool: one byte
  /// each, non-zero = true). Returns false (frame unchanged) if it would not fit, if the
  /// arguments are invalid (type, count 0, value_len != count * size, flags) or if the
  /// frame is a heartbeat.
  bool Add(uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, uint32_t seq,
           uint64_t source_time_ns, const void* value, size_t value_len);
  /// Add for a sender that checked the entry's fields once: `prefix` is EntryPrefix() of
  /// them (non-zero), `value_len` its value length. Same bytes as Add; false if it would
  /// not fit, if prefix is 0, or if the frame is a heartbeat or not begun.
  /// Inline for one 8-byte element (a double or int64 signal), the rest out of line.
  bool AddPrepared(uint64_t prefix, uint32_t seq, uint64_t source_time_ns, const void* value, size_t value_len) {
    if (value_len != 8 || !IsWordPrefix(prefix) || value == nullptr)
      return AddPreparedGeneric(prefix, seq, source_time_ns, value, value_len);
    uint64_t x;
    std::memcpy(&x, value, 8);
    return AddWord(prefix, seq, source_time_ns, x);
  }
  /// Whether `prefix` (an EntryPrefix) is that of a one-element int64 or double entry:
  /// then AddWord may encode it. A sender checks this once per signal, not per value.
  static bool IsWordPrefix(uint64_t prefix) {
    const uint8_t type = reinterpret_cast<const uint8_t*>(&prefix)[2];  // the entry's type byte
    return prefix != 0 && type < 8 && ((0x50u >> type) & 1);           // int64 (4) or double (6)
  }
  /// AddPrepared of an entry with IsWordPrefix(prefix) (the caller checked it once): `word`
  /// is the value's 8 bytes in host order. Only the room is checked here: false if it would
  /// not fit, if the frame is a heartbeat or not begun (limit_ - len_ is then too small).
  bool AddWord(uint64_t prefix, uint32_t seq, uint64_t source_time_ns, uint64_t word) {
    if (EntrySize(8) > limit_ - len_) return false;
    uint8_t* p = buf_ + len_;
    std::memcpy(p, &prefix, 8);
    be::Store<uint32_t>(p + 8, seq);
    be::Store<uint32_t>(p + 12, 0);
    be::Store<uint64_t>(p + 16, source_time_ns);
    be::Store<uint64_t>(p + kEntryHeaderSize, word);
    len_ += EntrySize(8);
    ++count_;
    return true;
  }
  /// Appends a fragment entry: bytes [offset, offset + part_len) of a value of
  /// total_len = count x element size bytes, `part` in host byte order. flags may hold
  /// kEntryEvent (kEntryFragment is implied). Returns false (frame unchanged) if it would
  /// not fit or the arguments break the rules of docs/protocol.md (element-aligned part
  /// and offset, a strict part of the value, total at most kMaxFragmentedValue).
  bool AddFragment(uint16_t signal, uint8_t type, uint8_t flags, uint16_t count, uint32_t seq,
                   uint64_t source_time_ns, uint32_t offset, const void* part, size_t part_len);
  /// Writes entry_count / payload_len into the header; returns the frame length
  /// without any auth tag, or 0 if Begin failed (cap < kHeaderSize, unknown flag bits)
  /// or a frame without kFlagHeartbeat has no entry (such a frame is invalid).
  /// If a tag will follow, pass kFlagAuth to Begin: the writer then keeps kAuthTagSize
  /// bytes free so that frame + tag <= kMaxFrameSize; the caller computes the tag over
  /// the returned bytes and stores it at buf + Finish().
  size_t Finish();
  size_t size() const { return len_; }
  uint16_t entries() const { return count_; }
  /// Bytes an entry with value_len value bytes takes on the wire (padded to 8).
  static size_t EntrySize(size_t value_len) { return kEntryHeaderSize + ((value_len + 7u) & ~size_t{7}); }
  /// Bytes a fragment entry with part_len part bytes takes on the wire.
  static size_t FragmentEntrySize(size_t part_len) { return kFragmentHeaderSize + EntrySize(part_len); }
  /// Whether a value_len-byte value fits one entry of a frame alone (else it travels in
  /// fragments); `auth`: frames carry a tag.
  static bool FitsOneFrame(size_t value_len, bool auth) {
    return kHeaderSize + EntrySize(value_len) + (auth ? kAuthTagSize : 0) <= kMaxFrameSize;
  }
  /// Largest part of a fragment entry alone in a frame (a multiple of 8, so of every
  /// element size): 1408 bytes, 1392 with a tag.
  static size_t MaxFragmentPart(bool auth) {
    return (kMaxFrameSize - kHeaderSize - kEntryHeaderSize - kFragmentHeaderSize - (auth ? kAuthTagSize : 0)) &
           ~size_t{7};
  }
  /// Summary frames only (kFlagSummary): reserves `n` (a multiple of 8) payload bytes for
  /// the caller to fill (summary.cpp); nullptr if it would not fit or the frame is no summary.
  uint8_t* ReserveBody(size_t n);

 private:
  bool AddPreparedGeneric(uint64_t prefix, uint32_t seq, uint64_t source_time_ns, const void* value,
                          size_t value_len);

  uint8_t* buf_;
  size_t cap_;
  size_t len_ = 0;     // 0 until a successful Begin
  size_t limit_ = 0;   // min(cap, kMaxFrameSize - tag room), set by Begin
  uint16_t count_ = 0;
};

/// Validates the whole frame (header and every entry) before anything is used. On kOk,
/// `h` is filled and entries can be walked with EntryIterator; otherwise `h` is untouched.
DecodeError DecodeHeader(const uint8_t* buf, size_t len, FrameHeader* h);

/// What a receiver expects of one signal's entries, for DecodeFrame: their first 8 bytes
/// (EntryPrefix) and their size on the wire. Not known (checked in full): prefix 0 and
/// a size no entry fits in, so one bounds compare also refuses an all-zero entry.
struct KnownEntry {
  uint64_t prefix = 0;
  uint32_t size = UINT32_MAX;  // kEntryHeaderSize + value_len (value_len is whole words)
  uint32_t unused = 0;
};
/// The KnownEntry of a signal whose entries start with `prefix` (EntryPrefix): known if
/// its value is whole 8-byte words of a non-bool type (value_len % 8 == 0), else not.
inline KnownEntry MakeKnownEntry(uint64_t prefix, uint8_t type, size_t value_len) {
  KnownEntry k;
  if (prefix != 0 && type != 1 && value_len % 8 == 0) {  // 1 = bool: its bytes need a check each
    k.prefix = prefix;
    k.size = static_cast<uint32_t>(kEntryHeaderSize + value_len);
  }
  return k;
}

/// DecodeHeader for a receiver that knows which entries to expect: known[signal] (for
/// signal < known_count) made by MakeKnownEntry. An entry that starts with its known
/// prefix is checked with one compare (plus its reserved word and bounds); every other
/// entry as DecodeHeader checks it. Same verdicts as DecodeHeader for any table built
/// that way (fuzz_decode checks).
DecodeError DecodeFrame(const uint8_t* buf, size_t len, FrameHeader* h, const KnownEntry* known,
                        size_t known_count);

/// Ethernet pads payloads shorter than this with zero bytes (a plain heartbeat is 32).
constexpr size_t kEthMinPayload = 46;
/// For frames received over raw Ethernet: if `len` <= kEthMinPayload, the frame declares a
/// shorter length and every byte after it is zero, returns that length; otherwise `len`.
size_t TrimEthernetPadding(const uint8_t* buf, size_t len);

/// Walks the entries of a frame already accepted by DecodeHeader. Inline: on the
/// receive path it is a handful of loads per entry.
class EntryIterator {
 public:
  EntryIterator(const uint8_t* buf, const FrameHeader& h)
      : p_(buf + kHeaderSize), left_(h.entry_count) {}
  bool Next(EntryView* e) {
    if (left_ == 0) return false;
    std::memcpy(&e->prefix, p_, 8);
    e->signal = be::Load<uint16_t>(p_);
    e->type = p_[2];
    e->flags = p_[3];
    e->count = be::Load<uint16_t>(p_ + 4);
    e->value_len = be::Load<uint16_t>(p_ + 6);
    e->seq = be::Load<uint32_t>(p_ + 8);
    e->source_time_ns = be::Load<uint64_t>(p_ + 16);
    const size_t head = EntryValueOffset(p_);
    e->total_len = head == kEntryHeaderSize ? e->value_len : be::Load<uint32_t>(p_ + kEntryHeaderSize);
    e->offset = head == kEntryHeaderSize ? 0 : be::Load<uint32_t>(p_ + kEntryHeaderSize + 4);
    e->value = p_ + head;
    p_ += head + ((e->value_len + 7u) & ~size_t{7});
    --left_;
    return true;
  }

 private:
  const uint8_t* p_;
  uint16_t left_;
};

/// One entry of a frame already accepted by DecodeHeader, read field by field where it
/// lies (a receive path that needs only some fields reads only those).
struct EntryRef {
  const uint8_t* p;
  uint64_t prefix() const {  // see EntryPrefix
    uint64_t w;
    std::memcpy(&w, p, 8);
    return w;
  }
  uint16_t signal() const { return be::Load<uint16_t>(p); }
  uint8_t type() const { return p[2]; }
  uint16_t count() const { return be::Load<uint16_t>(p + 4); }
  uint16_t value_len() const { return be::Load<uint16_t>(p + 6); }
  uint32_t seq() const { return be::Load<uint32_t>(p + 8); }
  uint64_t source_time_ns() const { return be::Load<uint64_t>(p + 16); }
  uint8_t flags() const { return p[3]; }
  /// The value (of a fragment entry: its part, after the sub-header).
  const uint8_t* value() const { return p + EntryValueOffset(p); }
  /// The entry after this one.
  EntryRef next() const { return EntryRef{p + EntryValueOffset(p) + ((value_len() + 7u) & ~size_t{7})}; }
  /// All fields, as EntryIterator gives them.
  void Read(EntryView* e) const;
};
/// The first entry of a frame accepted by DecodeHeader (h.entry_count of them follow).
inline EntryRef FirstEntry(const uint8_t* buf) { return EntryRef{buf + kHeaderSize}; }

inline void EntryRef::Read(EntryView* e) const {
  std::memcpy(&e->prefix, p, 8);
  e->signal = signal();
  e->type = type();
  e->flags = flags();
  e->count = count();
  e->value_len = value_len();
  e->seq = seq();
  e->source_time_ns = source_time_ns();
  const bool fragment = (flags() & kEntryFragment) != 0;
  e->total_len = fragment ? be::Load<uint32_t>(p + kEntryHeaderSize) : e->value_len;
  e->offset = fragment ? be::Load<uint32_t>(p + kEntryHeaderSize + 4) : 0;
  e->value = value();
}

/// Converts `count` elements of `type` from network to host byte order.
void ValueToHost(uint8_t type, const uint8_t* src, void* dst, size_t count);

}  // namespace wire
}  // namespace ccomm
