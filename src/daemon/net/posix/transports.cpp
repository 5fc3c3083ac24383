// SPDX-License-Identifier: Apache-2.0
// The transports of a Linux build (transport.h): raw Ethernet and UDP.
#include "daemon/net/transport.h"

namespace ccomm {

extern const TransportProvider kRawTransport;  // transport_raw.cpp
extern const TransportProvider kUdpTransport;  // transport_udp.cpp
const TransportProvider* const kTransports[] = {&kRawTransport, &kUdpTransport, nullptr};

}  // namespace ccomm
