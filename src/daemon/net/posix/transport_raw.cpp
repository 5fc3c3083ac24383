// SPDX-License-Identifier: Apache-2.0
// Raw Ethernet: AF_PACKET/SOCK_DGRAM on one interface, filtered by EtherType in the
// kernel. The kernel builds the Ethernet header from the destination MAC.
#include <arpa/inet.h>
#include <errno.h>
#include <linux/filter.h>
#include <linux/if_packet.h>
#include <net/ethernet.h>
#include <net/if.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <vector>

#include "common/platform.h"
#include "config/config.h"
#include "daemon/net/transport.h"
#include "daemon/net/posix/txtime_socket.h"
#include "wire/wire.h"

namespace ccomm {


namespace {

struct RawState {
  int fd = -1;
  int ifindex = 0;
  uint16_t ethertype = 0;
};

RawState* State(Transport* t) { return static_cast<RawState*>(t->state); }

// Where a frame to `to` goes: this socket's interface and EtherType, the peer's MAC.
struct sockaddr_ll AddressTo(const RawState& st, const PeerAddress& to) {
  struct sockaddr_ll sll;
  memset(&sll, 0, sizeof sll);
  sll.sll_family = AF_PACKET;
  sll.sll_ifindex = st.ifindex;
  sll.sll_protocol = htons(st.ethertype);
  sll.sll_halen = 6;
  memcpy(sll.sll_addr, to.mac, 6);
  return sll;
}

int RawSend(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len) {
  struct sockaddr_ll sll = AddressTo(*State(t), to);
  if (t->txtime_asap_ns)  // send on the cycle: launch times on (send_cycle.h)
    return SendWithLaunch(State(t)->fd, &sll, sizeof sll, frame, len, TaiNs() + t->txtime_asap_ns);
  ssize_t n = sendto(State(t)->fd, frame, len, 0, reinterpret_cast<struct sockaddr*>(&sll), sizeof sll);
  return n == static_cast<ssize_t>(len) ? 0 : -errno;
}

ssize_t RawRecv(Transport* t, uint8_t* buf, size_t cap, PeerAddress* from) {
  for (;;) {
    struct sockaddr_ll sll;
    socklen_t sl = sizeof sll;
    ssize_t n = recvfrom(State(t)->fd, buf, cap, MSG_TRUNC, reinterpret_cast<struct sockaddr*>(&sll), &sl);
    if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -errno;
    if (sll.sll_pkttype == PACKET_OUTGOING) continue;  // our own frames, looped back
    if (static_cast<size_t>(n) > cap) return -EMSGSIZE;
    if (n == 0) return -ENODATA;  // an empty frame; 0 means "timeout" to the caller
    memcpy(from->mac, sll.sll_addr, 6);
    // Ethernet pads payloads to 46 bytes: drop (zero) padding after the declared frame.
    n = static_cast<ssize_t>(wire::TrimEthernetPadding(buf, static_cast<size_t>(n)));
    return n;
  }
}

int RawDrops(Transport* t, uint32_t* drops) { return platform::SocketDrops(State(t)->fd, drops); }

// Joins the group MACs (so a NIC with a multicast filter passes them) and attaches a
// classic BPF filter: a frame to a ccomm group MAC (kGroupMacPrefix) is accepted only for
// the groups joined; anything else (unicast to us, broadcast) passes as before. Software
// links (veth, bridges) deliver every multicast frame: without the filter a board would
// wake for every producer of the system, not only those it exchanges with.
int RawJoinGroups(Transport* t, const PeerAddress* groups, size_t n, std::string* error) {
  RawState* st = State(t);
  for (size_t i = 0; i < n; ++i) {
    struct packet_mreq mr;
    memset(&mr, 0, sizeof mr);
    mr.mr_ifindex = st->ifindex;
    mr.mr_type = PACKET_MR_MULTICAST;
    mr.mr_alen = 6;
    memcpy(mr.mr_address, groups[i].mac, 6);
    if (setsockopt(st->fd, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &mr, sizeof mr) != 0) {
      int e = errno;
      *error = std::string("cannot join multicast MAC group: ") + strerror(e);
      return -e;
    }
  }
  // Program: A = dest MAC bytes 0-3; not the prefix -> accept; A = bytes 4-5; one
  // compare per group (at most kMaxNodes, so every jump fits the 8-bit offsets).
  std::vector<sock_filter> prog;
  const uint32_t prefix = (uint32_t{kGroupMacPrefix[0]} << 24) | (uint32_t{kGroupMacPrefix[1]} << 16) |
                          (uint32_t{kGroupMacPrefix[2]} << 8) | kGroupMacPrefix[3];
  const uint8_t compares = static_cast<uint8_t>(n);
  prog.push_back(BPF_STMT(BPF_LD | BPF_W | BPF_ABS, static_cast<uint32_t>(SKF_LL_OFF)));
  // Not a group frame: jump over the half-word load, the compares and the drop.
  prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, prefix, 0, static_cast<uint8_t>(compares + 2)));
  prog.push_back(BPF_STMT(BPF_LD | BPF_H | BPF_ABS, static_cast<uint32_t>(SKF_LL_OFF + 4)));
  for (size_t i = 0; i < n; ++i) {
    const uint32_t tail = (uint32_t{groups[i].mac[4]} << 8) | groups[i].mac[5];
    const uint8_t to_accept = static_cast<uint8_t>(n - i);  // over the remaining compares and the drop
    prog.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, tail, to_accept, 0));
  }
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, 0));           // another node's group: drop
  prog.push_back(BPF_STMT(BPF_RET | BPF_K, 0xFFFFFFFFu));  // accept whole frame
  struct sock_fprog fprog;
  fprog.len = static_cast<unsigned short>(prog.size());
  fprog.filter = prog.data();
  if (setsockopt(st->fd, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof fprog) != 0) {
    int e = errno;
    *error = std::string("cannot attach the group filter to the raw socket: ") + strerror(e);
    return -e;
  }
  return 0;
}

void RawClose(Transport* t) {
  RawState* st = State(t);
  if (st->fd >= 0) close(st->fd);
  delete st;
}

// --- send on the cycle (send_cycle.h, txtime_socket.h) ---
int RawSendAt(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len, uint64_t launch_tai_ns) {
  struct sockaddr_ll sll = AddressTo(*State(t), to);
  return SendWithLaunch(State(t)->fd, &sll, sizeof sll, frame, len, launch_tai_ns);
}
void RawTxtimeSetup(Transport* t, TxtimeProbe* probe, std::string* detail) {
  probe->platform = true;
  probe->tai_minus_realtime_ns = TaiMinusRealtimeNs();
  if (!probe->want) return;
  char name[IF_NAMESIZE] = "?";
  if_indextoname(static_cast<unsigned>(State(t)->ifindex), name);
  ProbeEtf(State(t)->ifindex, probe, detail);
  *detail = std::string(name) + ": " + *detail;
  // Only for a usable ETF: a socket of priority kTxtimePriority without launch times would
  // have its frames dropped there.
  if (probe->etf && probe->etf_delta_ns < probe->lead_ns) probe->socket_error = EnableTxtime(State(t)->fd);
}
uint32_t RawTxtimeDrops(Transport* t) { return DrainTxtimeErrors(State(t)->fd); }

const TransportOps kRawOps = {"raw", RawSend, RawRecv, RawDrops, RawJoinGroups, RawClose,
                              RawTxtimeSetup, RawSendAt, RawTxtimeDrops};

}  // namespace

static int OpenRawTransport(const NetworkConfig& net, const NodeConfig& self, int recv_timeout_ms,
                            Transport* out, std::string* error) {
  int fd = socket(AF_PACKET, SOCK_DGRAM | SOCK_CLOEXEC, htons(net.ethertype));
  if (fd < 0) {
    int e = errno;
    *error = std::string("cannot open a raw packet socket: ") + strerror(e);
    if (e == EPERM || e == EACCES)
      *error += " (raw Ethernet needs CAP_NET_RAW: run ccommd as root or with that capability, "
                "or use transport=\"udp\" / ccommd --transport udp)";
    return -e;
  }
  unsigned ifindex = if_nametoindex(self.interface.c_str());
  if (ifindex == 0) {
    *error = "no network interface '" + self.interface + "' (node '" + self.name + "')";
    close(fd);
    return -ENODEV;
  }
  struct sockaddr_ll sll;
  memset(&sll, 0, sizeof sll);
  sll.sll_family = AF_PACKET;
  sll.sll_protocol = htons(net.ethertype);
  sll.sll_ifindex = static_cast<int>(ifindex);
  if (bind(fd, reinterpret_cast<struct sockaddr*>(&sll), sizeof sll) != 0) {
    int e = errno;
    *error = "cannot bind raw socket to " + self.interface + ": " + strerror(e);
    close(fd);
    return -e;
  }
  int one = 1;
#ifdef PACKET_IGNORE_OUTGOING
  setsockopt(fd, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof one);
#endif
  (void)one;
  struct timeval tv = {recv_timeout_ms / 1000, (recv_timeout_ms % 1000) * 1000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  RawState* st = new RawState;
  st->fd = fd;
  st->ifindex = static_cast<int>(ifindex);
  st->ethertype = net.ethertype;
  out->ops = &kRawOps;
  out->state = st;
  return 0;
}

extern const TransportProvider kRawTransport = {"raw", TransportKind::kRaw, OpenRawTransport};

}  // namespace ccomm
