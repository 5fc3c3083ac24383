// SPDX-License-Identifier: Apache-2.0
// Stop requests on POSIX (stop_request.h): SIGTERM and SIGINT stop, SIGHUP asks for a
// reload; the main thread takes them synchronously (sigtimedwait), the I/O threads block them.
//
// The reload answer: `ccommd --reload PID` sends SIGHUP by sigqueue with kReloadAsk as
// its value and waits for SIGUSR1 from PID, whose value says applied (1) or not (0). Only
// a SIGHUP carrying that value is answered: a plain kill -HUP's sender may be gone, and
// SIGUSR1 would end whatever process has its pid now. `--reload PID --at T` asks with
// kReloadAtAsk and gets two answers: armed (2), then applied (1) or not (0).
#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "common/platform.h"
#include "daemon/service/stop_request.h"

namespace ccomm {
namespace stop {
namespace {

constexpr int kReloadAsk = 0x43524c44;    // "CRLD"
constexpr int kReloadAtAsk = 0x43524c41;  // "CRLA"
constexpr int kAnswerSignal = SIGUSR1;

sigset_t g_set;
int g_requester = 0;

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
  siginfo_t info = {};
  const int sig = sigtimedwait(&g_set, &info, &ts);
  if (sig == SIGTERM || sig == SIGINT) return Request::kStop;
  if (sig == SIGHUP) {
    const bool queued = info.si_code == SI_QUEUE;
    const bool at = queued && info.si_value.sival_int == kReloadAtAsk;
    g_requester = queued && (at || info.si_value.sival_int == kReloadAsk) ? info.si_pid : 0;
    return at ? Request::kReloadAt : Request::kReload;
  }
  return Request::kNone;
}

void RequestStop() { kill(getpid(), SIGTERM); }

int ReloadRequester() { return g_requester; }

void AnswerReload(int requester, ReloadAnswer answer) {
  if (requester <= 0) return;
  union sigval v;
  v.sival_int = static_cast<int>(answer);
  if (sigqueue(requester, kAnswerSignal, v) != 0)
    Log(LogLevel::kWarning, "cannot answer the reload request of pid %d: %s", requester, strerror(errno));
}

namespace {

// Sends `ask` to pid and waits for its answers: kArmed (only with on_armed) restarts the
// wait with done_timeout_ms; kApplied / kRefused end it.
int Ask(int pid, int ask, int first_timeout_ms, int done_timeout_ms, void (*on_armed)(void*), void* ctx) {
  // Blocked before asking: the answer may come before sigtimedwait runs.
  sigset_t answer;
  sigemptyset(&answer);
  sigaddset(&answer, kAnswerSignal);
  pthread_sigmask(SIG_BLOCK, &answer, nullptr);
  union sigval v;
  v.sival_int = ask;
  if (sigqueue(pid, SIGHUP, v) != 0) return -errno;
  uint64_t deadline = platform::MonotonicNs() + uint64_t(first_timeout_ms) * 1000000;
  for (;;) {
    const uint64_t now = platform::MonotonicNs();
    if (now >= deadline) return -ETIMEDOUT;
    const uint64_t left = deadline - now;
    struct timespec ts = {static_cast<time_t>(left / 1000000000), static_cast<long>(left % 1000000000)};
    siginfo_t info = {};
    const int sig = sigtimedwait(&answer, &info, &ts);
    if (sig == kAnswerSignal && info.si_pid == pid) {
      const int a = info.si_value.sival_int;
      if (a == static_cast<int>(ReloadAnswer::kArmed) && on_armed) {
        on_armed(ctx);
        on_armed = nullptr;
        deadline = platform::MonotonicNs() + uint64_t(done_timeout_ms) * 1000000;
        continue;
      }
      return a == static_cast<int>(ReloadAnswer::kApplied) ? 1 : 0;
    }
    if (sig < 0 && errno != EINTR && errno != EAGAIN) return -errno;
  }
}

}  // namespace

int AskReload(int pid, int timeout_ms) { return Ask(pid, kReloadAsk, timeout_ms, 0, nullptr, nullptr); }

int AskReloadAt(int pid, int armed_timeout_ms, int done_timeout_ms, void (*on_armed)(void*), void* ctx) {
  return Ask(pid, kReloadAtAsk, armed_timeout_ms, done_timeout_ms, on_armed, ctx);
}

}  // namespace stop
}  // namespace ccomm
