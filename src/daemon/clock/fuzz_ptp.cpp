// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: ptp4l management answers (ptp_state.h), as any process that can write
// to ccommd's management socket could send them. Parsed or refused, never read out of bounds;
// the state machine takes whatever parses.
#include <stddef.h>
#include <stdint.h>

#include "daemon/clock/ptp_state.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ccomm::ptp::Reply r;
  if (ccomm::ptp::ParseReply(data, size, &r)) {
    ccomm::ptp::Monitor m;
    m.Answer(r, 1);
    m.Evaluate(2);
  }
  return 0;
}
