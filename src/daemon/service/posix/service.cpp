// SPDX-License-Identifier: Apache-2.0
// No service manager protocol beyond the process (POSIX: systemd, service.h).
#include "daemon/service/service.h"

namespace ccomm {
namespace service {

int Main(int argc, char** argv, int (*run)(int, char**)) { return run(argc, argv); }

}  // namespace service
}  // namespace ccomm
