// SPDX-License-Identifier: Apache-2.0
// ccommd.exe as a Windows service (service.h). The service's command line is
// `ccommd.exe --service -c C:\...\signals.xml [--node NAME] ...`; the service control
// manager's stop and shutdown controls become a stop request (stop_request.h), so the
// daemon shuts down as after Ctrl-C. A service has no console: its log goes to
// ccommd.log beside ccommd.exe (appended); what ccommd prints before it logs (a bad
// configuration) is lost, and only its exit status reaches the service manager
// (sc query: SERVICE_EXIT_CODE 1 bad config, 3 start failure): check a file first with
// ccommd.exe --check. The service is reported running when ccommd
// starts, stopped with ccommd's exit status (service-specific error) when it ends.
#include <stdio.h>
#include <string.h>

#include <string>
#include <vector>

// clang-format off
#include <windows.h>
// clang-format on

#include "common/platform.h"
#include "daemon/service/service.h"
#include "daemon/service/stop_request.h"

namespace ccomm {
namespace service {
namespace {

int (*g_run)(int, char**) = nullptr;
std::vector<char*> g_args;  // argv without --service
int g_exit = 0;
SERVICE_STATUS_HANDLE g_handle = nullptr;

void Report(DWORD state, int exit_status) {
  SERVICE_STATUS st = {};
  st.dwServiceType = SERVICE_WIN32_OWN_PROCESS;
  st.dwCurrentState = state;
  st.dwControlsAccepted = state == SERVICE_RUNNING ? SERVICE_ACCEPT_STOP | SERVICE_ACCEPT_SHUTDOWN : 0;
  st.dwWin32ExitCode = exit_status ? ERROR_SERVICE_SPECIFIC_ERROR : NO_ERROR;
  st.dwServiceSpecificExitCode = static_cast<DWORD>(exit_status);
  st.dwWaitHint = state == SERVICE_STOP_PENDING ? 5000 : 0;
  SetServiceStatus(g_handle, &st);
}

DWORD WINAPI OnControl(DWORD control, DWORD /*type*/, void* /*data*/, void* /*context*/) {
  switch (control) {
    case SERVICE_CONTROL_STOP:
    case SERVICE_CONTROL_SHUTDOWN:
      Report(SERVICE_STOP_PENDING, 0);
      stop::RequestStop();
      return NO_ERROR;
    case SERVICE_CONTROL_INTERROGATE: return NO_ERROR;
    default: return ERROR_CALL_NOT_IMPLEMENTED;
  }
}

void WINAPI ServiceMain(DWORD /*argc*/, LPWSTR* /*argv*/) {
  g_handle = RegisterServiceCtrlHandlerExW(L"ccommd", OnControl, nullptr);
  if (!g_handle) return;
  Report(SERVICE_RUNNING, 0);
  g_exit = g_run(static_cast<int>(g_args.size()) - 1, g_args.data());
  Report(SERVICE_STOPPED, g_exit);
}

}  // namespace

int Main(int argc, char** argv, int (*run)(int, char**)) {
  if (argc < 2 || strcmp(argv[1], "--service") != 0) return run(argc, argv);
  g_run = run;
  g_args.push_back(argv[0]);
  for (int i = 2; i < argc; ++i) g_args.push_back(argv[i]);
  g_args.push_back(nullptr);
  char exe[MAX_PATH];
  const DWORD n = GetModuleFileNameA(nullptr, exe, sizeof exe);
  if (n > 0 && n < sizeof exe) {
    std::string log(exe, n);
    log = log.substr(0, log.find_last_of("\\/") + 1) + "ccommd.log";
    // A service's standard handles are not open (the C runtime's stderr has no
    // descriptor and cannot be reopened): the log lines go to the file instead.
    SetLogFile(log.c_str());
  }
  SERVICE_TABLE_ENTRYW table[] = {{const_cast<LPWSTR>(L"ccommd"), ServiceMain}, {nullptr, nullptr}};
  if (!StartServiceCtrlDispatcherW(table)) {
    fprintf(stderr, "ccommd: --service: not started by the service control manager (error %lu); install it with "
            "sc create ccommd binPath= \"C:\\...\\ccommd.exe --service -c C:\\...\\signals.xml\"\n", GetLastError());
    return 2;
  }
  return g_exit;
}

}  // namespace service
}  // namespace ccomm
