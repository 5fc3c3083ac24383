// SPDX-License-Identifier: Apache-2.0
// The receive thread's wait cut short on POSIX (io_threads.h): SIGUSR2 interrupts its
// blocking call (it waits in its socket up to recv_timeout_ms); its loop treats EINTR as
// "nothing yet" and looks whether it should stop.
#include "daemon/service/io_threads.h"

#include <signal.h>
#include <time.h>

namespace ccomm {
namespace {

void Interrupted(int) {}

}  // namespace

// A stop or a reload cuts the wait short (SIGUSR2): no need to wake for nothing.
int IdleRecvTimeoutMs() { return 1000; }

void PrepareIoInterrupt() {
  struct sigaction sa = {};
  sa.sa_handler = Interrupted;  // no SA_RESTART: the blocking call returns EINTR
  sigemptyset(&sa.sa_mask);
  sigaction(SIGUSR2, &sa, nullptr);
}

// Interrupts `t` every millisecond meanwhile: a signal that came while the thread was
// between blocking calls would be missed, and one more costs nothing.
void JoinInterrupting(pthread_t t) {
  for (;;) {
    pthread_kill(t, SIGUSR2);
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += 1000 * 1000;
    if (ts.tv_nsec >= 1000000000L) {
      ts.tv_sec += 1;
      ts.tv_nsec -= 1000000000L;
    }
    if (pthread_timedjoin_np(t, nullptr, &ts) == 0) return;
  }
}

}  // namespace ccomm
