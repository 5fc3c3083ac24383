// SPDX-License-Identifier: Apache-2.0
// What a transport learns at start-up about launch times on its socket and the
// interface's qdiscs (send on the cycle: engine/send_cycle.h decides from it; the Linux
// calls are net/posix/txtime_socket.cpp). No OS header: every platform's transport fills it.
#pragma once

#include <cstdint>

namespace ccomm {

// The socket priority ccommd's frames carry when launch times are on; the documented
// qdisc set-up (docs/usage.md) maps it to the ETF band. 3 is a priority no IP TOS maps
// to, and one an unprivileged socket may set (0..6).
constexpr int kTxtimePriority = 3;

// What start-up learnt about the socket and the interface's qdiscs (txtime_*.cpp).
struct TxtimeProbe {
  bool want = true;         // in: launch_time="auto"; else only the clocks are read
  uint64_t lead_ns = 0;     // in: SO_TXTIME is turned on only for an ETF qdisc whose delta is below it
  int64_t tai_minus_realtime_ns = 0;  // CLOCK_TAI - CLOCK_REALTIME (whole seconds; 0 where unknown)
  bool platform = false;    // SO_TXTIME exists here
  int socket_error = 0;     // errno of setsockopt(SO_TXTIME), 0 = accepted
  bool etf = false;         // an ETF qdisc (CLOCK_TAI) takes frames of priority kTxtimePriority
  uint64_t etf_delta_ns = 0;
};

}  // namespace ccomm
