// SPDX-License-Identifier: Apache-2.0
// UDP/IPv4: unicast to each peer's ip, or one multicast group. Needs no privileges.
#include <arpa/inet.h>
#include <errno.h>
#include <net/if.h>
#include <netinet/in.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "common/platform.h"
#include "daemon/transport.h"

namespace ccomm {
namespace {

struct UdpState {
  int fd = -1;
  uint16_t port = 0;  // network order
};

UdpState* State(Transport* t) { return static_cast<UdpState*>(t->state); }

int UdpSend(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len) {
  struct sockaddr_in sin;
  memset(&sin, 0, sizeof sin);
  sin.sin_family = AF_INET;
  sin.sin_addr.s_addr = to.ipv4;
  sin.sin_port = to.port ? to.port : State(t)->port;
  ssize_t n = sendto(State(t)->fd, frame, len, 0, reinterpret_cast<struct sockaddr*>(&sin), sizeof sin);
  return n == static_cast<ssize_t>(len) ? 0 : -errno;
}

ssize_t UdpRecv(Transport* t, uint8_t* buf, size_t cap, PeerAddress* from) {
  struct sockaddr_in sin;
  socklen_t sl = sizeof sin;
  ssize_t n = recvfrom(State(t)->fd, buf, cap, MSG_TRUNC, reinterpret_cast<struct sockaddr*>(&sin), &sl);
  if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -errno;
  if (static_cast<size_t>(n) > cap) return -EMSGSIZE;
  if (n == 0) return -ENODATA;  // an empty datagram; 0 means "timeout" to the caller
  from->ipv4 = sin.sin_addr.s_addr;
  from->port = sin.sin_port;
  return n;
}

int UdpDrops(Transport* t, uint32_t* drops) { return platform::SocketDrops(State(t)->fd, drops); }

void UdpClose(Transport* t) {
  UdpState* st = State(t);
  if (st->fd >= 0) close(st->fd);
  delete st;
}

const TransportOps kUdpOps = {"udp", UdpSend, UdpRecv, UdpDrops, UdpClose};

}  // namespace

bool PeerAddressFor(const NetworkConfig& net, const NodeConfig& peer, TransportKind kind,
                    PeerAddress* out) {
  *out = PeerAddress();
  if (kind == TransportKind::kRaw) {
    if (peer.has_mac) memcpy(out->mac, peer.mac, 6);
    return true;
  }
  const std::string& ip = peer.multicast.empty() ? peer.ip : peer.multicast;
  struct in_addr a;
  if (ip.empty() || inet_pton(AF_INET, ip.c_str(), &a) != 1) return false;
  out->ipv4 = a.s_addr;
  out->port = htons(net.udp_port);
  return true;
}

int OpenUdpTransport(const NetworkConfig& net, const NodeConfig& self, int recv_timeout_ms,
                     Transport* out, std::string* error) {
  int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    *error = std::string("cannot open a UDP socket: ") + strerror(errno);
    return -errno;
  }
  int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  struct sockaddr_in sin;
  memset(&sin, 0, sizeof sin);
  sin.sin_family = AF_INET;
  sin.sin_port = htons(net.udp_port);
  // Unicast: bind to our own address so two nodes may share a host (loopback tests).
  // Multicast: bind to any and join the group.
  if (self.multicast.empty() && !self.ip.empty()) inet_pton(AF_INET, self.ip.c_str(), &sin.sin_addr);
  if (bind(fd, reinterpret_cast<struct sockaddr*>(&sin), sizeof sin) != 0) {
    int e = errno;
    *error = "cannot bind UDP " + (self.ip.empty() ? std::string("*") : self.ip) + ":" +
             std::to_string(net.udp_port) + ": " + strerror(e);
    if (e == EADDRNOTAVAIL) *error += " (is " + self.ip + " configured on this host?)";
    close(fd);
    return -e;
  }
  if (!self.multicast.empty()) {
    struct ip_mreqn mr;
    memset(&mr, 0, sizeof mr);
    inet_pton(AF_INET, self.multicast.c_str(), &mr.imr_multiaddr);
    mr.imr_ifindex = self.interface.empty() ? 0 : static_cast<int>(if_nametoindex(self.interface.c_str()));
    if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) != 0) {
      int e = errno;
      *error = "cannot join multicast group " + self.multicast + ": " + strerror(e);
      close(fd);
      return -e;
    }
    unsigned char loop = 0;  // our own datagrams are not for us
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop);
    if (mr.imr_ifindex) setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &mr, sizeof mr);
  }
  struct timeval tv = {recv_timeout_ms / 1000, (recv_timeout_ms % 1000) * 1000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  UdpState* st = new UdpState;
  st->fd = fd;
  st->port = htons(net.udp_port);
  out->ops = &kUdpOps;
  out->state = st;
  return 0;
}

}  // namespace ccomm
