// SPDX-License-Identifier: Apache-2.0
// Least privilege on Windows (privileges.h): nothing to drop. ccommd.exe needs no
// privilege for UDP; a service runs as the account the service manager gives it
// (docs/install.md, "Windows"), which is where its rights are chosen.
#include "daemon/security/privileges.h"

namespace ccomm {

int DropPrivileges(const RealtimeConfig& /*rt*/, bool /*realtime*/, std::string* summary) {
  *summary = "no capabilities to drop on Windows (runs with the rights of its account)";
  return 0;
}

}  // namespace ccomm
