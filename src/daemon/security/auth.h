// SPDX-License-Identifier: Apache-2.0
// Optional per-frame authentication (docs/protocol.md, "Authentication trailer"):
// a 16-byte BLAKE2b tag keyed with a pre-shared 32-byte key, plus per-sender replay
// protection over the frame sequence number and the sender's send time.
//
// Everything here is preallocated and allocation-free after key loading, so the tag
// computation and the replay check run on ccommd's real-time paths.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "wire/wire.h"

namespace ccomm {
namespace auth {

constexpr size_t kKeyBytes = 32;
constexpr size_t kTagBytes = wire::kAuthTagSize;

/// True if ccommd was built with libsodium (CCOMM_WITH_SODIUM); without it a configured
/// key file is refused at start-up rather than silently ignored.
bool Available();

/// Reads a key file: exactly 32 raw bytes, or 64 hex digits (optionally followed by a
/// newline). The file must be a regular file owned by root or by the effective user,
/// with no permission bits for group or others (chmod 600/400): a key others can read
/// authenticates nothing. Returns 0 or -errno with a message saying what to fix.
int LoadKeyFile(const std::string& path, uint8_t key[kKeyBytes], std::string* error);

class FrameAuth {
 public:
  FrameAuth() = default;
  FrameAuth(const FrameAuth&) = delete;
  FrameAuth& operator=(const FrameAuth&) = delete;
  ~FrameAuth();  // wipes the key

  /// Loads the key from `path` (see LoadKeyFile) and enables authentication.
  int Load(const std::string& path, std::string* error);
  /// Enables authentication with `key` (tests).
  void SetKey(const uint8_t key[kKeyBytes]);
  bool enabled() const { return enabled_; }
  /// Frame flag bits this node sets on every frame it sends (kFlagAuth or 0).
  uint8_t frame_flags() const { return enabled_ ? wire::kFlagAuth : 0; }

  /// [rt] Writes the tag of frame[0, len) to tag[0, kTagBytes).
  void Sign(const uint8_t* frame, size_t len, uint8_t* tag) const;
  /// [rt] Checks a frame already accepted by wire::DecodeHeader (`len` includes the tag
  /// if the frame has one). With a key: the frame must carry a tag (kFlagAuth) and it
  /// must match, compared in constant time. Without a key: a tagged frame is refused,
  /// so a key configured on one side only shows up as a counter, not as a silent downgrade.
  bool Accept(const uint8_t* frame, size_t len, uint8_t flags) const;

 private:
  bool enabled_ = false;
  uint8_t key_[kKeyBytes] = {};
};

enum class ReplayVerdict { kAccept, kRestart, kReplay };

/// Anti-replay state for one sender. Frames of one sender incarnation carry increasing
/// `seq` (+1 per frame) and non-decreasing `send_ns` (the sender's CLOCK_MONOTONIC).
/// A frame is accepted once: either ahead of the newest one (seq and time forward), or
/// late but inside a kWidth-frame window and not seen yet (reordering). A lower seq
/// with a later send time is a restarted sender (same boot: its clock went on); a
/// rebooted board (clock back near 0) is accepted only after the peer was silent for
/// longer than `peer_timeout_ns` and only if its clock is younger than that silence,
/// i.e. the board can really have booted after its last frame. Anything else is a
/// duplicate or a replay of a recorded frame.
class ReplayWindow {
 public:
  static constexpr uint32_t kWidth = 64;

  /// [rt] Decides on a frame that passed every other check; updates the state on
  /// kAccept / kRestart. `now_ns` is the receiver's CLOCK_MONOTONIC.
  ReplayVerdict Check(uint32_t seq, uint64_t send_ns, uint64_t now_ns, uint64_t peer_timeout_ns);

 private:
  void Reset(uint32_t seq, uint64_t send_ns, uint64_t now_ns);

  bool seen_ = false;
  uint32_t top_ = 0;          // highest accepted seq
  uint64_t bits_ = 0;         // bit i: seq top_ - i was accepted
  uint64_t top_send_ns_ = 0;  // send time of the frame with seq top_
  uint64_t floor_ns_ = 0;     // send time of the first frame of this incarnation
  uint64_t last_rx_ns_ = 0;   // receiver's clock at the last accepted frame
};

}  // namespace auth
}  // namespace ccomm
