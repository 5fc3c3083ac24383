// SPDX-License-Identifier: Apache-2.0
// Starting and stopping the I/O threads (io_threads.h).
#include "daemon/service/io_threads.h"

#include <string.h>

#include "common/platform.h"
#include "daemon/engine/daemon.h"

namespace ccomm {
namespace {

void* TxThread(void* d) {
  static_cast<Daemon*>(d)->RunTx();
  return nullptr;
}
void* RxThread(void* d) {
  static_cast<Daemon*>(d)->RunRx();
  return nullptr;
}

}  // namespace

int StartIo(Daemon& daemon, IoThreads* io) {
  static bool prepared = false;
  if (!prepared) PrepareIoInterrupt();
  prepared = true;
  if (int e = pthread_create(&io->tx, nullptr, TxThread, &daemon)) {
    Log(LogLevel::kError, "ccommd: cannot start the send thread: %s", strerror(e));
    return e;
  }
  if (int e = pthread_create(&io->rx, nullptr, RxThread, &daemon)) {
    Log(LogLevel::kError, "ccommd: cannot start the receive thread: %s", strerror(e));
    daemon.RequestStop();
    pthread_join(io->tx, nullptr);
    return e;
  }
  io->running = true;
  return 0;
}

void StopIo(Daemon& daemon, IoThreads* io) {
  daemon.RequestStop();
  if (!io->running) return;
  pthread_join(io->tx, nullptr);
  JoinInterrupting(io->rx);
  io->running = false;
}

}  // namespace ccomm
