// SPDX-License-Identifier: Apache-2.0
// A build without libsodium: frame authentication is unavailable (auth_crypto.h). ccommd
// refuses to start with auth_key_file rather than run unauthenticated, so Tag and
// TagsEqual are never reached; they fail closed all the same.
#include <string.h>

#include "daemon/security/auth_crypto.h"

namespace ccomm {
namespace auth {
namespace crypto {

const bool kAvailable = false;

int Init() { return 0; }

void Wipe(void* p, size_t n) {
  volatile uint8_t* v = static_cast<volatile uint8_t*>(p);
  while (n--) *v++ = 0;
}

void Tag(const uint8_t*, size_t, const uint8_t*, uint8_t tag[kTagBytes]) { memset(tag, 0, kTagBytes); }

bool TagsEqual(const uint8_t*, const uint8_t*) { return false; }

}  // namespace crypto
}  // namespace auth
}  // namespace ccomm
