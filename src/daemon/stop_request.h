// SPDX-License-Identifier: Apache-2.0
// How ccommd is asked to stop (or to reload, which it refuses): signals on POSIX
// (SIGTERM, SIGINT, SIGHUP; stop_request_posix.cpp), the console's Ctrl-C / Ctrl-Break /
// close and the service manager's stop on Windows (stop_request_windows.cpp). main()
// waits for a request in its supervision loop.
#pragma once

namespace ccomm {
namespace stop {

enum class Request { kNone, kStop, kReload };

/// Routes stop requests to Wait: on POSIX blocks the signals in the calling thread and the
/// threads it creates afterwards (so only Wait takes them); on Windows installs the
/// console control handler. Call once, before the I/O threads are created.
void Install();
/// Waits up to `timeout_ms` for a request; kNone when none came.
Request Wait(int timeout_ms);
/// A stop request from inside the process (the Windows service's stop control).
void RequestStop();

}  // namespace stop
}  // namespace ccomm
