// SPDX-License-Identifier: Apache-2.0
// Stop requests on POSIX (stop_request.h): SIGTERM and SIGINT stop, SIGHUP asks for a
// reload; the main thread takes them synchronously (sigtimedwait), the I/O threads block them.
#include <pthread.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include "daemon/stop_request.h"

namespace ccomm {
namespace stop {
namespace {

sigset_t g_set;

}  // namespace

void Install() {
  sigemptyset(&g_set);
  sigaddset(&g_set, SIGTERM);
  sigaddset(&g_set, SIGINT);
  sigaddset(&g_set, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &g_set, nullptr);
}

Request Wait(int timeout_ms) {
  struct timespec ts = {timeout_ms / 1000, (timeout_ms % 1000) * 1000L * 1000L};
  const int sig = sigtimedwait(&g_set, nullptr, &ts);
  if (sig == SIGTERM || sig == SIGINT) return Request::kStop;
  if (sig == SIGHUP) return Request::kReload;
  return Request::kNone;
}

void RequestStop() { kill(getpid(), SIGTERM); }

}  // namespace stop
}  // namespace ccomm
