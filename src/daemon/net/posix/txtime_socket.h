// SPDX-License-Identifier: Apache-2.0
// Launch times on a socket (send on the cycle, send_cycle.h): the Linux calls behind the
// transports' txtime hooks (net/posix/txtime_socket.cpp). Start-up only, except
// SendWithLaunch (the send path: one sendmsg, no allocation) and DrainTxtimeErrors
// (supervision tick: non-blocking reads of the socket's error queue).
#pragma once

#include <sys/socket.h>
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/net/txtime_probe.h"

namespace ccomm {

/// SO_TXTIME (CLOCK_TAI, drops reported on the error queue) and SO_PRIORITY
/// kTxtimePriority on `fd`: 0 or errno. CLOCK_TAI needs CAP_NET_ADMIN at this call (a
/// kernel rule); the socket keeps the option after ccommd drops its capabilities.
int EnableTxtime(int fd);
/// Reads the qdiscs of interface `ifindex` over rtnetlink (no privileges) and fills
/// p->etf / p->etf_delta_ns: an ETF qdisc on CLOCK_TAI that frames of priority
/// kTxtimePriority reach (root etf; prio with the band of that priority; mqprio with every
/// queue of its traffic class). `detail` says what was found.
void ProbeEtf(int ifindex, TxtimeProbe* p, std::string* detail);
/// sendmsg of one frame with SCM_TXTIME = `launch_tai_ns`; 0 or -errno.
int SendWithLaunch(int fd, const void* name, socklen_t namelen, const uint8_t* frame, size_t len,
                   uint64_t launch_tai_ns);
/// CLOCK_TAI now (vDSO).
uint64_t TaiNs();
/// CLOCK_TAI - CLOCK_REALTIME: the kernel's TAI offset, whole seconds (0 unless set).
int64_t TaiMinusRealtimeNs();
/// Frames the qdisc reported dropped (SO_EE_ORIGIN_TXTIME on the error queue) since the
/// last call; reads at most 64 messages.
uint32_t DrainTxtimeErrors(int fd);

}  // namespace ccomm
