// SPDX-License-Identifier: Apache-2.0
// Stop requests on Windows (stop_request.h): Ctrl-C, Ctrl-Break and closing the console
// window stop ccommd.exe (a console control handler, which Windows calls on a thread
// of its own), as does the service manager's stop (RequestStop). An auto-reset event
// wakes the waiting main thread. After a close event Windows ends the process once the
// handler returns, so the handler gives main up to 5 s to shut down first (main's
// return ends the process, and the waiting handler with it).
// clang-format off
#include <windows.h>
// clang-format on

#include <errno.h>

#include <atomic>

#include "daemon/service/stop_request.h"

namespace ccomm {
namespace stop {
namespace {

HANDLE g_event = nullptr;
std::atomic<bool> g_stop{false};

BOOL WINAPI OnConsoleControl(DWORD type) {
  switch (type) {
    case CTRL_C_EVENT:
    case CTRL_BREAK_EVENT:
      RequestStop();
      return TRUE;
    case CTRL_CLOSE_EVENT:
    case CTRL_LOGOFF_EVENT:
    case CTRL_SHUTDOWN_EVENT:
      RequestStop();
      Sleep(5000);
      return TRUE;
    default:
      return FALSE;
  }
}

}  // namespace

void Install() {
  g_event = CreateEventW(nullptr, FALSE, FALSE, nullptr);
  SetConsoleCtrlHandler(OnConsoleControl, TRUE);
}

Request Wait(int timeout_ms) {
  if (!g_stop.load()) WaitForSingleObject(g_event, static_cast<DWORD>(timeout_ms));
  return g_stop.load() ? Request::kStop : Request::kNone;
}

void RequestStop() {
  g_stop.store(true);
  SetEvent(g_event);
}

// No reload on Windows (no SIGHUP): restart the service to load a new file.
int ReloadRequester() { return 0; }
void AnswerReload(int, ReloadAnswer) {}
int AskReload(int, int) { return -ENOSYS; }
int AskReloadAt(int, int, int, void (*)(void*), void*) { return -ENOSYS; }

}  // namespace stop
}  // namespace ccomm
