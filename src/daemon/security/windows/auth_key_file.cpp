// SPDX-License-Identifier: Apache-2.0
// The pre-shared key file on Windows (auth.h, LoadKeyFile): not read. Its safety check
// (no access for group or others, owned by the service account) is a POSIX mode check;
// the Windows one would read the file's ACL. The Windows build has no libsodium either,
// so FrameAuth::Load refuses a configured key file before this is reached.
#include <errno.h>

#include "daemon/security/auth.h"

namespace ccomm {
namespace auth {

int LoadKeyFile(const std::string& path, uint8_t* /*key*/, std::string* error) {
  *error = "auth key file " + path + ": frame authentication is not built on Windows (no libsodium, and the "
           "key file's access check is POSIX)";
  return -ENOTSUP;
}

}  // namespace auth
}  // namespace ccomm
