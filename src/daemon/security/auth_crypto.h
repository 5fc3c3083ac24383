// SPDX-License-Identifier: Apache-2.0
// The cryptographic primitives frame authentication needs, one unit per build:
// auth_crypto_sodium.cpp (libsodium's keyed BLAKE2b) or auth_crypto_none.cpp (no
// libsodium: authentication unavailable, ccommd refuses a key). CMake picks the unit.
#pragma once

#include <cstddef>
#include <cstdint>

#include "daemon/security/auth.h"

namespace ccomm {
namespace auth {
namespace crypto {

/// Whether this build can authenticate frames at all.
extern const bool kAvailable;
/// 0, or -1 if the library failed to initialise.
int Init();
/// Zeroes key material in a way the compiler does not remove.
void Wipe(void* p, size_t n);
/// tag = keyed BLAKE2b-128 of frame[0..len) (never called when !kAvailable).
void Tag(const uint8_t* frame, size_t len, const uint8_t key[kKeyBytes], uint8_t tag[kTagBytes]);
/// Constant-time comparison of two tags.
bool TagsEqual(const uint8_t a[kTagBytes], const uint8_t b[kTagBytes]);

}  // namespace crypto
}  // namespace auth
}  // namespace ccomm
