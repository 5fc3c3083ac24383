// SPDX-License-Identifier: Apache-2.0
// `ccommd --reload PID --at T` on Windows (switch_request.h): not built there, as the
// reload it extends (service/windows/stop_request.cpp).
#include "common/platform.h"
#include "daemon/service/switch_request.h"

namespace ccomm {
namespace switch_at {

int Request(const std::string&, int, uint64_t) {
  Log(LogLevel::kError, "ccommd: --reload --at is not available on Windows (restart the service to apply a file)");
  return 1;
}

}  // namespace switch_at
}  // namespace ccomm
