// SPDX-License-Identifier: Apache-2.0
// The socket address of a UDP frame to a peer, the same on every platform: the one piece
// the two UDP units (transport_udp.cpp, net/windows/transport_udp.cpp) share. Each includes
// its platform's socket headers before this one.
#pragma once

#include <string.h>

#include "daemon/net/transport.h"

namespace ccomm {

/// `to`'s address and port (network order); a peer without a port of its own is reached
/// on the transport's (`default_port`, network order).
inline struct sockaddr_in UdpAddressTo(const PeerAddress& to, uint16_t default_port) {
  struct sockaddr_in sin;
  memset(&sin, 0, sizeof sin);
  sin.sin_family = AF_INET;
  sin.sin_addr.s_addr = to.ipv4;
  sin.sin_port = to.port ? to.port : default_port;
  return sin;
}

}  // namespace ccomm
