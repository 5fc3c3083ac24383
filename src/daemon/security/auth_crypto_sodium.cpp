// SPDX-License-Identifier: Apache-2.0
// Frame authentication primitives with libsodium (see auth_crypto.h).
#include <sodium.h>

#include "daemon/security/auth_crypto.h"

namespace ccomm {
namespace auth {
namespace crypto {

const bool kAvailable = true;

int Init() { return sodium_init() < 0 ? -1 : 0; }

void Wipe(void* p, size_t n) { sodium_memzero(p, n); }

void Tag(const uint8_t* frame, size_t len, const uint8_t key[kKeyBytes], uint8_t tag[kTagBytes]) {
  crypto_generichash(tag, kTagBytes, frame, len, key, kKeyBytes);
}

bool TagsEqual(const uint8_t a[kTagBytes], const uint8_t b[kTagBytes]) { return sodium_memcmp(a, b, kTagBytes) == 0; }

}  // namespace crypto
}  // namespace auth
}  // namespace ccomm
