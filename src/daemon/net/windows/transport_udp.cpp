// SPDX-License-Identifier: Apache-2.0
// UDP/IPv4 through Winsock: the Windows unit of transport_udp.cpp, behind the same
// function table (transport.h). Unicast to each peer's ip, or one multicast group, or
// the fan-out groups. What differs from Linux, and why:
// - Windows delivers a group only to the sockets that joined it (no IP_MULTICAST_ALL to
//   turn off) and has no per-socket limit of 20 groups: one socket joins them all.
// - An ICMP port unreachable (a peer whose ccommd is not up yet) makes the next recvfrom
//   fail with WSAECONNRESET unless SIO_UDP_CONNRESET is off: it is turned off.
// - A datagram larger than the buffer fails with WSAEMSGSIZE (Linux: MSG_TRUNC's length).
// - Winsock counts no drops per socket: socket_drops says -ENOSYS.
// - The default receive buffer is small (64 KiB): ccommd asks for 4 MiB.
#include <errno.h>
#include <stdio.h>
#include <string.h>

// clang-format off
#include <winsock2.h>  // before windows.h
#include <ws2tcpip.h>
#include <mswsock.h>   // SIO_UDP_CONNRESET
#include <iphlpapi.h>  // if_nametoindex
// clang-format on
#undef interface  // objbase.h's macro; NodeConfig has a member of that name

#include "common/platform.h"
#include "config/config.h"
#include "daemon/net/transport.h"
#include "daemon/net/transport_udp_address.h"

namespace ccomm {
namespace {

constexpr int kReceiveBufferBytes = 4 << 20;

struct UdpState {
  SOCKET sock = INVALID_SOCKET;
  uint16_t port = 0;         // network order
  struct in_addr group_if;  // interface for group membership: the node's address, or an index
};

UdpState* State(Transport* t) { return static_cast<UdpState*>(t->state); }

// The errno for a Winsock error, so callers and messages treat both platforms alike.
int ErrnoOf(int wsa) {
  switch (wsa) {
    case WSAEADDRNOTAVAIL: return EADDRNOTAVAIL;
    case WSAEADDRINUSE: return EADDRINUSE;
    case WSAEACCES: return EACCES;
    case WSAEMSGSIZE: return EMSGSIZE;
    case WSAENETDOWN: return ENETDOWN;
    case WSAENETUNREACH: return ENETUNREACH;
    case WSAEHOSTUNREACH: return EHOSTUNREACH;
    case WSAENOBUFS: return ENOBUFS;
    case WSAEINVAL: return EINVAL;
    case WSAEWOULDBLOCK: return EAGAIN;
    case WSAETIMEDOUT: return ETIMEDOUT;
    case WSAECONNRESET: return ECONNRESET;
    case WSAENOTSOCK: return EBADF;
    default: return EIO;
  }
}

std::string WsaText(int wsa) {
  return std::string(strerror(ErrnoOf(wsa))) + " (Winsock error " + std::to_string(wsa) + ")";
}

int UdpSend(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len) {
  struct sockaddr_in sin = UdpAddressTo(to, State(t)->port);
  const int n = sendto(State(t)->sock, reinterpret_cast<const char*>(frame), static_cast<int>(len), 0,
                       reinterpret_cast<struct sockaddr*>(&sin), sizeof sin);
  return n == static_cast<int>(len) ? 0 : -ErrnoOf(WSAGetLastError());
}

ssize_t UdpRecv(Transport* t, uint8_t* buf, size_t cap, PeerAddress* from) {
  struct sockaddr_in sin;
  int sl = sizeof sin;
  const int n = recvfrom(State(t)->sock, reinterpret_cast<char*>(buf), static_cast<int>(cap), 0,
                         reinterpret_cast<struct sockaddr*>(&sin), &sl);
  if (n < 0) {
    const int e = WSAGetLastError();
    if (e == WSAEMSGSIZE) return -EMSGSIZE;
    // Timeout (SO_RCVTIMEO), or a late ICMP report: nothing to read.
    return (e == WSAETIMEDOUT || e == WSAEWOULDBLOCK || e == WSAEINTR || e == WSAECONNRESET) ? 0 : -ErrnoOf(e);
  }
  if (n == 0) return -ENODATA;  // an empty datagram; 0 means "timeout" to the caller
  from->ipv4 = sin.sin_addr.s_addr;
  from->port = sin.sin_port;
  return n;
}

int UdpDrops(Transport* t, uint32_t* drops) {
  (void)t;
  *drops = 0;
  return -ENOSYS;
}

int Join(UdpState* st, uint32_t group_be, std::string* error) {
  struct ip_mreq mr;
  memset(&mr, 0, sizeof mr);
  mr.imr_multiaddr.s_addr = group_be;
  mr.imr_interface = st->group_if;
  if (setsockopt(st->sock, IPPROTO_IP, IP_ADD_MEMBERSHIP, reinterpret_cast<const char*>(&mr), sizeof mr) == 0)
    return 0;
  const int e = WSAGetLastError();
  char a[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &mr.imr_multiaddr, a, sizeof a);
  *error = std::string("cannot join multicast group ") + a + ": " + WsaText(e) +
           " (give the node interface= or ip= of the interface to use)";
  return -ErrnoOf(e);
}

int UdpJoinGroups(Transport* t, const PeerAddress* groups, size_t n, std::string* error) {
  for (size_t i = 0; i < n; ++i)
    if (int r = Join(State(t), groups[i].ipv4, error)) return r;
  return 0;
}

void UdpClose(Transport* t) {
  UdpState* st = State(t);
  if (st->sock != INVALID_SOCKET) closesocket(st->sock);
  delete st;
  WSACleanup();
}

// No launch times on Windows (no SO_TXTIME): a send cycle sleeps until its instants (send_cycle.h).
const TransportOps kUdpOps = {"udp", UdpSend, UdpRecv, UdpDrops, UdpJoinGroups, UdpClose, nullptr, nullptr, nullptr};

int Fail(UdpState* st, int e, std::string* error, const std::string& what) {
  *error = what + ": " + WsaText(e);
  if (st->sock != INVALID_SOCKET) closesocket(st->sock);
  delete st;
  WSACleanup();
  return -ErrnoOf(e);
}

}  // namespace

static int OpenUdpTransport(const NetworkConfig& net, const NodeConfig& self, int recv_timeout_ms,
                            Transport* out, std::string* error) {
  WSADATA wsa;
  if (int e = WSAStartup(MAKEWORD(2, 2), &wsa)) {
    *error = "cannot start Winsock: " + WsaText(e);
    return -ErrnoOf(e);
  }
  UdpState* st = new UdpState;
  st->port = htons(net.udp_port);
  st->group_if.s_addr = INADDR_ANY;
  uint32_t self_ipv4 = 0;
  if (!self.ip.empty()) platform::ParseIpv4(self.ip.c_str(), &self_ipv4);
  // Group membership and multicast sends use interface= where Windows knows that name
  // (an index goes where the address would, as 0.0.0.index), else the node's ip= (as on
  // Linux, an unknown name is not an error: one file serves boards and PCs).
  const unsigned index = self.interface.empty() ? 0 : if_nametoindex(self.interface.c_str());
  st->group_if.s_addr = index ? htonl(index) : self_ipv4;
  st->sock = socket(AF_INET, SOCK_DGRAM, IPPROTO_UDP);
  if (st->sock == INVALID_SOCKET) return Fail(st, WSAGetLastError(), error, "cannot open a UDP socket");
  SetHandleInformation(reinterpret_cast<HANDLE>(st->sock), HANDLE_FLAG_INHERIT, 0);
  BOOL off = FALSE;
  DWORD got = 0;
  WSAIoctl(st->sock, SIO_UDP_CONNRESET, &off, sizeof off, nullptr, 0, &got, nullptr, nullptr);
  BOOL one = TRUE;
  setsockopt(st->sock, SOL_SOCKET, SO_REUSEADDR, reinterpret_cast<const char*>(&one), sizeof one);
  // Windows' default receive buffer (64 KiB: some 25 frames of 36 doubles) overflows when
  // the receive thread is held up for 25 ms, which a desktop PC does: room for about a
  // second at 1 kHz instead (best effort; the system may grant less).
  const int rcvbuf = kReceiveBufferBytes;
  setsockopt(st->sock, SOL_SOCKET, SO_RCVBUF, reinterpret_cast<const char*>(&rcvbuf), sizeof rcvbuf);
  struct sockaddr_in sin;
  memset(&sin, 0, sizeof sin);
  sin.sin_family = AF_INET;
  sin.sin_port = st->port;
  // Unicast: bind to our own address so two nodes may share a host (loopback tests).
  // Multicast (a node group, or fan-out groups): bind to any and join the group(s).
  const bool fanout = net.fanout == Fanout::kMulticast;
  if (self.multicast.empty() && !fanout) sin.sin_addr.s_addr = self_ipv4;
  if (bind(st->sock, reinterpret_cast<struct sockaddr*>(&sin), sizeof sin) != 0) {
    const int e = WSAGetLastError();
    std::string what = "cannot bind UDP " + (self.ip.empty() ? std::string("*") : self.ip) + ":" +
                       std::to_string(net.udp_port);
    const int r = Fail(st, e, error, what);
    if (e == WSAEADDRNOTAVAIL) *error += " (is " + self.ip + " configured on this host?)";
    return r;
  }
  if (!self.multicast.empty()) {
    uint32_t group = 0;
    platform::ParseIpv4(self.multicast.c_str(), &group);
    std::string join_error;
    if (Join(st, group, &join_error) != 0) {
      *error = join_error;
      const int e = WSAGetLastError();
      closesocket(st->sock);
      delete st;
      WSACleanup();
      return -ErrnoOf(e);
    }
    DWORD loop = 0;  // our own datagrams are not for us
    setsockopt(st->sock, IPPROTO_IP, IP_MULTICAST_LOOP, reinterpret_cast<const char*>(&loop), sizeof loop);
  }
  if (fanout) {
    // Looped back so nodes sharing a host hear each other (a node never joins its own).
    DWORD loop = 1;
    setsockopt(st->sock, IPPROTO_IP, IP_MULTICAST_LOOP, reinterpret_cast<const char*>(&loop), sizeof loop);
  }
  if (!self.multicast.empty() || fanout)  // sent from the node's interface (its address peers check)
    setsockopt(st->sock, IPPROTO_IP, IP_MULTICAST_IF, reinterpret_cast<const char*>(&st->group_if),
               sizeof st->group_if);
  const DWORD timeout = static_cast<DWORD>(recv_timeout_ms);  // Winsock takes milliseconds
  setsockopt(st->sock, SOL_SOCKET, SO_RCVTIMEO, reinterpret_cast<const char*>(&timeout), sizeof timeout);
  out->ops = &kUdpOps;
  out->state = st;
  return 0;
}

extern const TransportProvider kUdpTransport = {"udp", TransportKind::kUdp, OpenUdpTransport};

}  // namespace ccomm
