// SPDX-License-Identifier: Apache-2.0
// The transports of a Windows build (transport.h): UDP only; raw Ethernet needs Linux's
// packet sockets (a node with transport="raw" is refused: RawEthernetUnavailable).
#include "daemon/net/transport.h"

namespace ccomm {

extern const TransportProvider kUdpTransport;  // transport_udp.cpp
const TransportProvider* const kTransports[] = {&kUdpTransport, nullptr};

}  // namespace ccomm
