// SPDX-License-Identifier: Apache-2.0
// The receive thread's wait on Windows (io_threads.h): not cut short. There is no reload
// there (windows/stop_request.cpp), so only a stop waits, up to recv_timeout_ms.
#include "daemon/service/io_threads.h"

namespace ccomm {

// A stop waits the receive thread's socket timeout out.
int IdleRecvTimeoutMs() { return 50; }

void PrepareIoInterrupt() {}
void JoinInterrupting(pthread_t t) { pthread_join(t, nullptr); }

}  // namespace ccomm
