// SPDX-License-Identifier: Apache-2.0
// The engine's two I/O threads (the send thread, Daemon::RunTx; the receive thread,
// Daemon::RunRx) as ccommd starts them after Daemon::Start and again after each reload
// (io_threads.cpp), and stops them for a stop or a reload: at once, not after the
// receive thread's socket timeout. How the receive thread's blocking call is cut short is
// the platform's (posix/io_interrupt.cpp: SIGUSR2; windows/io_interrupt.cpp: it is not, and a
// stop waits up to recv_timeout_ms: there is no reload there).
#pragma once

#include <pthread.h>

namespace ccomm {

class Daemon;

struct IoThreads {
  pthread_t tx{}, rx{};
  bool running = false;
};

/// Starts both threads; 0, or the error number (logged; then none runs).
int StartIo(Daemon& daemon, IoThreads* io);
/// Stops both (Daemon::RequestStop) and joins them. The send thread is woken by
/// RequestStop's doorbell and not interrupted: a signal in its sendto would drop a frame
/// whose values already count as sent.
void StopIo(Daemon& daemon, IoThreads* io);

// The platform's part (posix/ or windows/io_interrupt.cpp), for io_threads.cpp.
/// Once, before the first receive thread starts: what lets JoinInterrupting cut its wait short.
void PrepareIoInterrupt();
/// Joins the receive thread `t`, cutting its blocking call short where the platform can.
void JoinInterrupting(pthread_t t);
/// How long the receive thread may wait in its socket while nothing arrives (each turn
/// also counts for the watchdog, so main.cpp caps it at a quarter of the watchdog's
/// interval): long where JoinInterrupting cuts the wait short (an idle receive thread then
/// wakes only for frames), short where a stop has to wait it out.
int IdleRecvTimeoutMs();

}  // namespace ccomm
