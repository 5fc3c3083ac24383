// SPDX-License-Identifier: Apache-2.0
// UDP/IPv4: unicast to each peer's ip, or one multicast group. Needs no privileges.
#include <arpa/inet.h>
#include <errno.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <ifaddrs.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>

#include "common/platform.h"
#include "config/config.h"
#include "daemon/net/transport.h"
#include "daemon/net/transport_udp_address.h"
#include "daemon/net/posix/txtime_socket.h"

namespace ccomm {
namespace {

// Linux lets one socket join at most net.ipv4.igmp_max_memberships groups (default 20).
// A node consuming from more producers gets more sockets, bound like the first, each
// joining up to that many; then Recv polls them all (one more system call per frame,
// only on such a node).
constexpr size_t kMaxSockets = kMaxNodes + 1;  // every group on its own socket at worst

struct UdpState {
  int fd = -1;        // sends, and receives unicast and its share of the groups
  uint16_t port = 0;  // network order
  int ifindex = 0;    // interface for group membership (0: by address below, or any)
  uint32_t self_ipv4 = 0;  // network order, 0 if none
  int timeout_ms = 0;      // Recv's bound
  size_t extra = 0;        // more receiving sockets (extra_fd[0..extra)), for groups only
  int extra_fd[kMaxSockets] = {};
  struct pollfd polled[kMaxSockets + 1];  // fd, then extra_fd: filled at join
  size_t next = 0;                        // round robin over the ready sockets
  std::atomic<uint32_t> txtime_drops{0};  // send on the cycle: ETF drops drained by UdpRecv's poll
};

UdpState* State(Transport* t) { return static_cast<UdpState*>(t->state); }

int UdpSend(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len) {
  struct sockaddr_in sin = UdpAddressTo(to, State(t)->port);
  if (t->txtime_asap_ns)  // send on the cycle: launch times on (send_cycle.h)
    return SendWithLaunch(State(t)->fd, &sin, sizeof sin, frame, len, TaiNs() + t->txtime_asap_ns);
  ssize_t n = sendto(State(t)->fd, frame, len, 0, reinterpret_cast<struct sockaddr*>(&sin), sizeof sin);
  return n == static_cast<ssize_t>(len) ? 0 : -errno;
}

ssize_t UdpRecv(Transport* t, uint8_t* buf, size_t cap, PeerAddress* from) {
  UdpState* st = State(t);
  int fd = st->fd, flags = MSG_TRUNC;
  if (st->extra) {
    const size_t n = st->extra + 1;
    const int r = poll(st->polled, n, st->timeout_ms);
    if (r <= 0) return r == 0 || errno == EINTR ? 0 : -errno;
    for (size_t i = 0; i < n; ++i) {
      const size_t k = (st->next + i) % n;
      if (st->polled[k].revents) {
        fd = st->polled[k].fd;
        st->next = k + 1;
        break;
      }
    }
    flags |= MSG_DONTWAIT;
    if (st->polled[0].revents & POLLERR) st->txtime_drops += DrainTxtimeErrors(st->fd);  // send on the cycle
  }
  struct sockaddr_in sin;
  socklen_t sl = sizeof sin;
  ssize_t n = recvfrom(fd, buf, cap, flags, reinterpret_cast<struct sockaddr*>(&sin), &sl);
  if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -errno;
  if (static_cast<size_t>(n) > cap) return -EMSGSIZE;
  if (n == 0) return -ENODATA;  // an empty datagram; 0 means "timeout" to the caller
  from->ipv4 = sin.sin_addr.s_addr;
  from->port = sin.sin_port;
  return n;
}

int UdpDrops(Transport* t, uint32_t* drops) {
  UdpState* st = State(t);
  int r = platform::SocketDrops(st->fd, drops);
  for (size_t i = 0; i < st->extra && r == 0; ++i) {
    uint32_t more = 0;
    r = platform::SocketDrops(st->extra_fd[i], &more);
    *drops += more;
  }
  return r;
}

// How many groups one socket may join here (net.ipv4.igmp_max_memberships).
size_t GroupsPerSocket() {
  unsigned long v = 20;  // the kernel's default
  if (FILE* f = fopen("/proc/sys/net/ipv4/igmp_max_memberships", "r")) {
    if (fscanf(f, "%lu", &v) != 1) v = 20;
    fclose(f);
  }
  return v ? v : 1;
}

// A further receiving socket for groups: bound like the first (SO_REUSEADDR, any
// address, the port) and receiving only the groups it joins (IP_MULTICAST_ALL off).
int OpenGroupSocket(uint16_t port_be, std::string* error) {
  int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    *error = std::string("cannot open a UDP socket for more multicast groups: ") + strerror(errno);
    return -errno;
  }
  int one = 1, zero = 0;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_ALL, &zero, sizeof zero);
  struct sockaddr_in sin;
  memset(&sin, 0, sizeof sin);
  sin.sin_family = AF_INET;
  sin.sin_port = port_be;
  if (bind(fd, reinterpret_cast<struct sockaddr*>(&sin), sizeof sin) != 0) {
    const int e = errno;
    *error = std::string("cannot bind a UDP socket for more multicast groups: ") + strerror(e);
    close(fd);
    return -e;
  }
  return fd;
}

// The IP layer delivers only joined groups to this socket (IP_MULTICAST_ALL is off),
// so a board never reads frames of producers it does not exchange with.
int UdpJoinGroups(Transport* t, const PeerAddress* groups, size_t n, std::string* error) {
  UdpState* st = State(t);
  const size_t per_socket = GroupsPerSocket();
  for (size_t i = 0; i < n; ++i) {
    int fd = st->fd;
    if (i >= per_socket) {
      const size_t k = i / per_socket - 1;
      if (k >= kMaxSockets) {
        *error = "more multicast groups than sockets allow (net.ipv4.igmp_max_memberships " +
                 std::to_string(per_socket) + "): raise it";
        return -ENOBUFS;
      }
      if (k == st->extra) {
        const int e = OpenGroupSocket(st->port, error);
        if (e < 0) return e;
        st->extra_fd[st->extra++] = e;
      }
      fd = st->extra_fd[k];
    }
    struct ip_mreqn mr;
    memset(&mr, 0, sizeof mr);
    mr.imr_multiaddr.s_addr = groups[i].ipv4;
    mr.imr_ifindex = st->ifindex;
    if (!st->ifindex) mr.imr_address.s_addr = st->self_ipv4;
    if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) != 0) {
      int e = errno;
      char a[INET_ADDRSTRLEN] = "?";
      inet_ntop(AF_INET, &groups[i].ipv4, a, sizeof a);
      *error = std::string("cannot join multicast group ") + a + ": " + strerror(e) +
               (e == ENODEV ? " (no multicast route: give the node interface=, or add a route for 224.0.0.0/4)"
                : e == ENOBUFS ? " (the host's limit of groups: sysctl net.ipv4.igmp_max_memberships)" : "");
      return -e;
    }
  }
  st->polled[0] = {st->fd, POLLIN, 0};
  for (size_t i = 0; i < st->extra; ++i) st->polled[i + 1] = {st->extra_fd[i], POLLIN, 0};
  return 0;
}

void UdpClose(Transport* t) {
  UdpState* st = State(t);
  for (size_t i = 0; i < st->extra; ++i) close(st->extra_fd[i]);
  if (st->fd >= 0) close(st->fd);
  delete st;
}

// --- send on the cycle (send_cycle.h, txtime_socket.h) ---
int UdpSendAt(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len, uint64_t launch_tai_ns) {
  struct sockaddr_in sin = UdpAddressTo(to, State(t)->port);
  return SendWithLaunch(State(t)->fd, &sin, sizeof sin, frame, len, launch_tai_ns);
}
// The qdiscs that count are those of interface= or, without it, of the interface with ip=.
void UdpTxtimeSetup(Transport* t, TxtimeProbe* probe, std::string* detail) {
  UdpState* st = State(t);
  probe->platform = true;
  probe->tai_minus_realtime_ns = TaiMinusRealtimeNs();
  if (!probe->want) return;
  int ifindex = st->ifindex;
  struct ifaddrs* list = nullptr;
  if (!ifindex && st->self_ipv4 && getifaddrs(&list) == 0) {
    for (struct ifaddrs* a = list; a; a = a->ifa_next)
      if (a->ifa_addr && a->ifa_addr->sa_family == AF_INET &&
          reinterpret_cast<struct sockaddr_in*>(a->ifa_addr)->sin_addr.s_addr == st->self_ipv4)
        ifindex = static_cast<int>(if_nametoindex(a->ifa_name));
    freeifaddrs(list);
  }
  if (!ifindex) {
    *detail = "no interface known (give the node interface=)";
    return;
  }
  char name[IF_NAMESIZE] = "?";
  if_indextoname(static_cast<unsigned>(ifindex), name);
  ProbeEtf(ifindex, probe, detail);
  *detail = std::string(name) + ": " + *detail;
  // Only for a usable ETF: a socket of priority kTxtimePriority without launch times would
  // have its frames dropped there.
  if (probe->etf && probe->etf_delta_ns < probe->lead_ns) probe->socket_error = EnableTxtime(st->fd);
}
uint32_t UdpTxtimeDrops(Transport* t) {
  UdpState* st = State(t);
  return DrainTxtimeErrors(st->fd) + st->txtime_drops.exchange(0, std::memory_order_relaxed);
}

const TransportOps kUdpOps = {"udp", UdpSend, UdpRecv, UdpDrops, UdpJoinGroups, UdpClose,
                              UdpTxtimeSetup, UdpSendAt, UdpTxtimeDrops};

}  // namespace

static int OpenUdpTransport(const NetworkConfig& net, const NodeConfig& self, int recv_timeout_ms,
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
  // Multicast (a node group, or fan-out groups): bind to any and join the group(s).
  const bool fanout = net.fanout == Fanout::kMulticast;
  if (self.multicast.empty() && !fanout && !self.ip.empty()) inet_pton(AF_INET, self.ip.c_str(), &sin.sin_addr);
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
  UdpState* st = new UdpState;
  st->ifindex = self.interface.empty() ? 0 : static_cast<int>(if_nametoindex(self.interface.c_str()));
  if (!self.ip.empty()) inet_pton(AF_INET, self.ip.c_str(), &st->self_ipv4);
  if (fanout) {
    // Only groups this socket joined (not every group any socket of the host joined);
    // looped back so nodes sharing a host hear each other (a node never joins its own).
    int zero = 0;
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_ALL, &zero, sizeof zero);
    unsigned char loop = 1;
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop);
    struct ip_mreqn mif;
    memset(&mif, 0, sizeof mif);
    mif.imr_ifindex = st->ifindex;
    mif.imr_address.s_addr = st->self_ipv4;  // also the source address peers check
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &mif, sizeof mif);
  }
  struct timeval tv = {recv_timeout_ms / 1000, (recv_timeout_ms % 1000) * 1000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  st->fd = fd;
  st->port = htons(net.udp_port);
  st->timeout_ms = recv_timeout_ms;
  out->ops = &kUdpOps;
  out->state = st;
  return 0;
}

extern const TransportProvider kUdpTransport = {"udp", TransportKind::kUdp, OpenUdpTransport};

}  // namespace ccomm
