// SPDX-License-Identifier: Apache-2.0
// Frame authentication with libsodium's keyed BLAKE2b (crypto_generichash, 16-byte
// output) and the per-sender replay window. See auth.h and docs/protocol.md.
#include "daemon/security/auth.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "daemon/security/auth_crypto.h"

namespace ccomm {
namespace auth {
namespace {

void Wipe(void* p, size_t n) { crypto::Wipe(p, n); }

}  // namespace

bool Available() { return crypto::kAvailable; }

FrameAuth::~FrameAuth() { Wipe(key_, sizeof key_); }

int FrameAuth::Load(const std::string& path, std::string* error) {
  if (!Available()) {
    *error = "auth_key_file is set but this ccommd was built without libsodium "
             "(CCOMM_WITH_SODIUM): refusing to run unauthenticated";
    return -ENOTSUP;
  }
  if (crypto::Init() != 0) {
    *error = "libsodium failed to initialise";
    return -EIO;
  }
  uint8_t key[kKeyBytes];
  int r = LoadKeyFile(path, key, error);
  if (r != 0) return r;
  SetKey(key);
  Wipe(key, sizeof key);
  return 0;
}

void FrameAuth::SetKey(const uint8_t key[kKeyBytes]) {
  memcpy(key_, key, kKeyBytes);
  enabled_ = Available();
}

void FrameAuth::Sign(const uint8_t* frame, size_t len, uint8_t* tag) const {
  crypto::Tag(frame, len, key_, tag);
}

bool FrameAuth::Accept(const uint8_t* frame, size_t len, uint8_t flags) const {
  const bool tagged = (flags & wire::kFlagAuth) != 0;
  if (!enabled_) return !tagged;
  if (!tagged || len < wire::kHeaderSize + kTagBytes) return false;
  uint8_t expect[kTagBytes];
  Sign(frame, len - kTagBytes, expect);
  return crypto::TagsEqual(expect, frame + len - kTagBytes);
}

void ReplayWindow::Reset(uint32_t seq, uint64_t send_ns, uint64_t now_ns) {
  seen_ = true;
  top_ = seq;
  bits_ = 1;
  top_send_ns_ = send_ns;
  floor_ns_ = send_ns;
  last_rx_ns_ = now_ns;
}

ReplayVerdict ReplayWindow::Check(uint32_t seq, uint64_t send_ns, uint64_t now_ns,
                                  uint64_t peer_timeout_ns) {
  if (!seen_) {
    Reset(seq, send_ns, now_ns);
    return ReplayVerdict::kAccept;
  }
  const int32_t d = static_cast<int32_t>(seq - top_);  // serial-number arithmetic
  if (d > 0 && send_ns >= top_send_ns_) {
    bits_ = static_cast<uint32_t>(d) >= kWidth ? 0 : bits_ << d;
    bits_ |= 1;
    top_ = seq;
    top_send_ns_ = send_ns;
    last_rx_ns_ = now_ns;
    return ReplayVerdict::kAccept;
  }
  if (d <= 0 && static_cast<uint32_t>(-static_cast<int64_t>(d)) < kWidth && send_ns <= top_send_ns_ &&
      send_ns >= floor_ns_) {
    const uint64_t bit = uint64_t{1} << static_cast<uint32_t>(-static_cast<int64_t>(d));
    if (bits_ & bit) return ReplayVerdict::kReplay;  // seen: duplicate or replay
    bits_ |= bit;                                     // late but new: reordered
    last_rx_ns_ = now_ns;
    return ReplayVerdict::kAccept;
  }
  // Outside the window, or inconsistent with it.
  if (send_ns > top_send_ns_) {
    // The sender's counter went back while its clock went on: its ccommd restarted.
    Reset(seq, send_ns, now_ns);
    return ReplayVerdict::kRestart;
  }
  const uint64_t silence = now_ns - last_rx_ns_;
  if (silence > peer_timeout_ns && send_ns <= silence) {
    // Both went back: the board rebooted, which fits only if its uptime is shorter than
    // the time we have not heard from it.
    Reset(seq, send_ns, now_ns);
    return ReplayVerdict::kRestart;
  }
  return ReplayVerdict::kReplay;
}

}  // namespace auth
}  // namespace ccomm
