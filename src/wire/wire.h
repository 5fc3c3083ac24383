// SPDX-License-Identifier: Apache-2.0
// ccomm wire format v1: fixed-width, network byte order. Specified in docs/protocol.md;
// the hex test vectors there are the ones wire_test.cpp checks.
//
// Encoding and decoding work on caller-provided buffers, never allocate and never read
// or write outside [buf, buf + len): they are safe on the daemon's real-time paths and
// on any bytes from the wire.
#pragma once

#include <cstddef>
#include <cstdint>

namespace ccomm {
namespace wire {

constexpr uint32_t kMagic = 0x43434D57;  // "CCMW"
constexpr uint8_t kVersion = 1;
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
  kEntryEvent = 1u << 0,  // entry is an event (queued), not a state (last value wins)
};

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
  const uint8_t* value = nullptr;
};

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
  /// Replaces the value, seq and source time of the (non-event) entry of `signal` already
  /// in this frame, re-encoded as Add does (same type and count). False if absent.
  bool Rewrite(uint16_t signal, uint32_t seq, uint64_t source_time_ns, const void* value);
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
  /// Summary frames only (kFlagSummary): reserves `n` (a multiple of 8) payload bytes for
  /// the caller to fill (summary.cpp); nullptr if it would not fit or the frame is no summary.
  uint8_t* ReserveBody(size_t n);

 private:
  uint8_t* buf_;
  size_t cap_;
  size_t len_ = 0;     // 0 until a successful Begin
  size_t limit_ = 0;   // min(cap, kMaxFrameSize - tag room), set by Begin
  uint16_t count_ = 0;
};

/// Validates the whole frame (header and every entry) before anything is used. On kOk,
/// `h` is filled and entries can be walked with EntryIterator; otherwise `h` is untouched.
DecodeError DecodeHeader(const uint8_t* buf, size_t len, FrameHeader* h);

/// Ethernet pads payloads shorter than this with zero bytes (a plain heartbeat is 32).
constexpr size_t kEthMinPayload = 46;
/// For frames received over raw Ethernet: if `len` <= kEthMinPayload, the frame declares a
/// shorter length and every byte after it is zero, returns that length; otherwise `len`.
size_t TrimEthernetPadding(const uint8_t* buf, size_t len);

/// Walks the entries of a frame already accepted by DecodeHeader.
class EntryIterator {
 public:
  EntryIterator(const uint8_t* buf, const FrameHeader& h)
      : p_(buf + kHeaderSize), left_(h.entry_count) {}
  bool Next(EntryView* e);

 private:
  const uint8_t* p_;
  uint16_t left_;
};

/// Converts `count` elements of `type` from network to host byte order.
void ValueToHost(uint8_t type, const uint8_t* src, void* dst, size_t count);

}  // namespace wire
}  // namespace ccomm
