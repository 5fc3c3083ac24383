// SPDX-License-Identifier: Apache-2.0
// The socket to ptp4l on Windows (ptp_state.h, Monitor): there is no ptp4l, so nothing is
// asked and the clock state stays "none" (ccomm_get_clock_state says so). A Windows PC
// that needs PTP time runs its own PTP client; docs/install.md, "Windows".
#include "daemon/clock/ptp_state.h"

namespace ccomm {
namespace ptp {

Monitor::~Monitor() {}
bool Monitor::OpenSocket() { return false; }
void Monitor::Poll(uint64_t /*now_ns*/) {}
void Monitor::Drain(uint64_t /*now_ns*/) {}

}  // namespace ptp
}  // namespace ccomm
