// SPDX-License-Identifier: Apache-2.0
// libccomm's real-time set-up and periodic sleep (ccomm.h): an application's own loop
// gets the platform layer's one implementation (common/public/platform_app.h), the same ccommd,
// ccomm-fmu, ccomm-ros2 and ccomm-latency use, instead of its own mlockall and
// clock_nanosleep; on Windows the same call does what that platform offers.
#include <errno.h>
#include <stdint.h>

#include "ccomm/ccomm.h"
#include "common/public/platform_app.h"

int ccomm_realtime_setup(int32_t cpu, int32_t lock_memory, int32_t fifo_priority, int32_t errors[3]) {
  ccomm::platform::RealtimeRequest request;
  request.cpu = cpu < 0 ? -1 : cpu;
  request.lock_memory = lock_memory != 0;
  request.fifo_priority = fifo_priority > 0 ? fifo_priority : 0;
  const ccomm::platform::RealtimeResult r = ccomm::platform::SetUpRealtime(request);
  if (errors) {
    errors[0] = r.cpu;
    errors[1] = r.lock_memory;
    errors[2] = r.fifo_priority;
  }
  return r.cpu == 0 && r.lock_memory == 0 && r.fifo_priority == 0 ? 0 : CCOMM_E_SYS;
}

int ccomm_sleep_until(int64_t deadline_ns) {
  if (deadline_ns < 0) return CCOMM_E_INVAL;
  const int r = ccomm::platform::SleepUntilNs(deadline_ns);
  return r == -EINTR ? 1 : 0;
}
