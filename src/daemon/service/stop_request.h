// SPDX-License-Identifier: Apache-2.0
// How ccommd is asked to stop or to reload: signals on POSIX (SIGTERM, SIGINT, SIGHUP;
// service/posix/stop_request.cpp; `ccommd --reload PID` sends its SIGHUP with sigqueue and waits
// for the answer, so that systemctl reload fails when the reload did), the console's Ctrl-C / Ctrl-Break /
// close and the service manager's stop on Windows (service/windows/stop_request.cpp). main()
// waits for a request in its supervision loop.
#pragma once

namespace ccomm {
namespace stop {

// kReloadAt: `ccommd --reload PID --at T` asks for a switch to CONFIG.staged at instant T
// (switch_request.h): checked now, applied at T (ccomm deploy's second phase).
enum class Request { kNone, kStop, kReload, kReloadAt };
/// What ccommd tells the process that asked: kArmed only for kReloadAt (checked, waiting for
/// the instant), then kApplied or kRefused.
enum class ReloadAnswer { kRefused = 0, kApplied = 1, kArmed = 2 };

/// Routes stop requests to Wait: on POSIX blocks the signals in the calling thread and the
/// threads it creates afterwards (so only Wait takes them); on Windows installs the
/// console control handler. Call once, before the I/O threads are created.
void Install();
/// Waits up to `timeout_ms` for a request; kNone when none came.
Request Wait(int timeout_ms);
/// A stop request from inside the process (the Windows service's stop control).
void RequestStop();

/// The process that asked for the last kReload and waits for the answer (`ccommd
/// --reload`), or 0 (a plain kill -HUP: nobody to answer).
int ReloadRequester();
/// Answers `requester` (from ReloadRequester). Nothing if it is 0.
void AnswerReload(int requester, ReloadAnswer answer);
/// `ccommd --reload PID`: asks daemon `pid` to reload and waits up to `timeout_ms` for
/// its answer. 1 applied, 0 refused (the daemon logged why), -errno if it could not ask
/// or no answer came (-ETIMEDOUT).
int AskReload(int pid, int timeout_ms);
/// `ccommd --reload PID --at T`: asks for kReloadAt; waits up to `armed_timeout_ms` for
/// kArmed (then calls `on_armed(ctx)`), then up to `done_timeout_ms` more for the outcome.
/// 1 applied, 0 refused or cancelled, -errno as AskReload (-ENOSYS where not built).
int AskReloadAt(int pid, int armed_timeout_ms, int done_timeout_ms, void (*on_armed)(void*), void* ctx);

}  // namespace stop
}  // namespace ccomm
