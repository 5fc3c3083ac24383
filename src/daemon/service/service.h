// SPDX-License-Identifier: Apache-2.0
// ccommd under a service manager that needs more than a process (Windows' service control
// manager): `ccommd.exe --service ARGS...` as the service's command line runs ccommd with
// ARGS as a Windows service (service/windows/service.cpp). On POSIX, systemd runs the plain
// process and this passes straight through (service/posix/service.cpp).
#pragma once

namespace ccomm {
namespace service {

/// Runs `run(argc, argv)`, as a service when argv[1] is "--service" where services exist.
/// Returns the exit status.
int Main(int argc, char** argv, int (*run)(int, char**));

}  // namespace service
}  // namespace ccomm
