// SPDX-License-Identifier: Apache-2.0
// Peer and group addresses of both transports and the provider lookup (transport.h): the
// same on every platform, so they live apart from the socket units (net/posix/,
// net/windows/).
#include <string.h>

#include "common/platform.h"
#include "config/config.h"
#include "daemon/net/transport.h"

namespace ccomm {
static_assert(kSummaryGroup == kMaxNodes, "the summary group follows the node groups");

namespace {

// Host to network byte order without the socket headers (htonl/htons).
uint32_t NetworkOrder32(uint32_t host) {
  const uint8_t b[4] = {static_cast<uint8_t>(host >> 24), static_cast<uint8_t>(host >> 16),
                        static_cast<uint8_t>(host >> 8), static_cast<uint8_t>(host)};
  uint32_t v;
  memcpy(&v, b, 4);
  return v;
}
uint16_t NetworkOrder16(uint16_t host) {
  const uint8_t b[2] = {static_cast<uint8_t>(host >> 8), static_cast<uint8_t>(host)};
  uint16_t v;
  memcpy(&v, b, 2);
  return v;
}

}  // namespace

PeerAddress GroupAddressFor(const NetworkConfig& net, uint32_t node_id, TransportKind kind) {
  PeerAddress a;
  if (kind == TransportKind::kRaw) {
    memcpy(a.mac, kGroupMacPrefix, 4);
    a.mac[4] = static_cast<uint8_t>(node_id >> 8);
    a.mac[5] = static_cast<uint8_t>(node_id);
    return a;
  }
  const uint8_t* b = net.multicast_base;
  const uint32_t host = ((uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | b[3]) + node_id;
  a.ipv4 = NetworkOrder32(host);
  a.port = NetworkOrder16(net.udp_port);
  return a;
}

bool PeerAddressFor(const NetworkConfig& net, const NodeConfig& peer, TransportKind kind,
                    PeerAddress* out) {
  *out = PeerAddress();
  if (kind == TransportKind::kRaw) {
    if (peer.has_mac) memcpy(out->mac, peer.mac, 6);
    return true;
  }
  const std::string& ip = peer.multicast.empty() ? peer.ip : peer.multicast;
  if (ip.empty() || !platform::ParseIpv4(ip.c_str(), &out->ipv4)) return false;
  out->port = NetworkOrder16(net.udp_port);
  return true;
}

const TransportProvider* FindTransport(TransportKind kind) {
  for (const TransportProvider* const* p = kTransports; *p; ++p)
    if ((*p)->kind == kind) return *p;
  return nullptr;
}

std::string RawEthernetUnavailable(const NodeConfig& self) {
  return "node '" + self.name + "' uses transport=\"raw\": raw Ethernet is Linux-only; give this node transport=\"udp\" "
         "(its peers reach it by ip=), or start ccommd with --transport udp";
}

}  // namespace ccomm
