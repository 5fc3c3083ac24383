// SPDX-License-Identifier: Apache-2.0
#include "daemon/net/foreign_frames.h"

#include <arpa/inet.h>
#include <errno.h>
#include <linux/filter.h>
#include <linux/if_ether.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "common/platform.h"
#include "wire/wire.h"

namespace ccomm {

namespace {

constexpr uint32_t kSnap = 64;  // Ethernet + IPv4 + UDP headers and the frame header's start
constexpr uint64_t kLogEveryNs = 10ull * 1000 * 1000 * 1000;
constexpr uint64_t kPollEveryNs = 100ull * 1000 * 1000;
constexpr uint32_t kMaxReadPerPoll = 8;

uint16_t Be16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }
uint32_t Be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

}  // namespace

int ForeignFrameWatch::Open(const NetworkConfig& net, const NodeConfig& self, TransportKind kind) {
  Close();
  kind_ = kind;
  ethertype_ = net.ethertype;
  udp_port_ = net.udp_port;
  // Protocol 0: the socket receives nothing until bound, after the filter is attached.
  int fd = socket(AF_PACKET, SOCK_RAW | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return -errno;
  // Accepts the first kSnap bytes of frames that carry the ccomm magic but that the
  // transport's socket does not get: at a raw node any other EtherType, or UDP; at a UDP
  // node any EtherType but IPv4 (raw frames), or UDP to another port. Never our own.
  const uint32_t own_type = kind == TransportKind::kRaw ? ethertype_ : 0x10000u;  // 16-bit loads never match
  const uint32_t own_port = kind == TransportKind::kUdp ? udp_port_ : 0x10000u;
  enum : uint8_t { kAccept = 16, kDrop = 17 };
  auto to = [](uint8_t target, uint8_t at) { return static_cast<uint8_t>(target - at - 1); };
  sock_filter code[] = {
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, static_cast<uint32_t>(SKF_AD_OFF + SKF_AD_PKTTYPE)),  // 0
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, PACKET_OUTGOING, to(kDrop, 1), 0),                   // 1
      BPF_STMT(BPF_LD | BPF_H | BPF_ABS, 12),                                                  // 2 EtherType
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, ETH_P_IP, to(7, 3), 0),                              // 3
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, own_type, to(kDrop, 4), 0),                          // 4
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, 14),                                                  // 5
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, wire::kMagic, to(kAccept, 6), to(kDrop, 6)),         // 6
      BPF_STMT(BPF_LD | BPF_B | BPF_ABS, 14 + 9),                                              // 7 protocol
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, IPPROTO_UDP, 0, to(kDrop, 8)),                       // 8
      BPF_STMT(BPF_LD | BPF_H | BPF_ABS, 14 + 6),                                              // 9 fragment
      BPF_JUMP(BPF_JMP | BPF_JSET | BPF_K, 0x1fff, to(kDrop, 10), 0),                          // 10
      BPF_STMT(BPF_LDX | BPF_B | BPF_MSH, 14),                                                 // 11 X = IHL
      BPF_STMT(BPF_LD | BPF_H | BPF_IND, 14 + 2),                                              // 12 dst port
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, own_port, to(kDrop, 13), 0),                         // 13
      BPF_STMT(BPF_LD | BPF_W | BPF_IND, 14 + 8),                                              // 14 payload
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, wire::kMagic, to(kAccept, 15), to(kDrop, 15)),       // 15
      BPF_STMT(BPF_RET | BPF_K, kSnap),                                                        // 16 accept
      BPF_STMT(BPF_RET | BPF_K, 0),                                                            // 17 drop
  };
  static_assert(sizeof code / sizeof code[0] == kDrop + 1, "jump targets count on this layout");
  struct sock_fprog fprog;
  fprog.len = static_cast<unsigned short>(sizeof code / sizeof code[0]);
  fprog.filter = code;
  int ifindex = 0;  // a UDP node without interface=: every interface
  if (!self.interface.empty()) ifindex = static_cast<int>(if_nametoindex(self.interface.c_str()));
  struct sockaddr_ll sll;
  memset(&sll, 0, sizeof sll);
  sll.sll_family = AF_PACKET;
  sll.sll_protocol = htons(ETH_P_ALL);
  sll.sll_ifindex = ifindex;
  if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof fprog) != 0 ||
      bind(fd, reinterpret_cast<struct sockaddr*>(&sll), sizeof sll) != 0) {
    const int e = errno;
    close(fd);
    return -e;
  }
  // No copy of what this board sends (Linux >= 4.20; the filter drops it otherwise): the
  // send path pays nothing for the watch.
  int one = 1;
  setsockopt(fd, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof one);
  int small = 4096;  // a few frames to describe; the count comes from the kernel
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  fd_ = fd;
  return 0;
}

void ForeignFrameWatch::Describe(const uint8_t* f, size_t n, char* out, size_t cap) const {
  const uint16_t type = Be16(f + 12);
  const uint8_t* frame = f + 14;
  size_t left = n - 14;
  char what[96];
  if (type == ETH_P_IP && n >= 14 + 20) {
    const size_t ihl = (f[14] & 15u) * 4;
    char src[INET_ADDRSTRLEN] = "?";
    inet_ntop(AF_INET, f + 14 + 12, src, sizeof src);
    const uint16_t port = n >= 14 + ihl + 4 ? Be16(f + 14 + ihl + 2) : 0;
    snprintf(what, sizeof what, "over UDP to port %u from %s", port, src);
    frame = f + 14 + ihl + 8;
    left = n >= 14 + ihl + 8 ? n - 14 - ihl - 8 : 0;
  } else {
    snprintf(what, sizeof what, "raw, EtherType 0x%04X, from %02x:%02x:%02x:%02x:%02x:%02x", type, f[6], f[7],
             f[8], f[9], f[10], f[11]);
  }
  const char* mine = kind_ == TransportKind::kRaw ? "raw" : "UDP";
  char setting[64];
  if (kind_ == TransportKind::kRaw) snprintf(setting, sizeof setting, "raw, EtherType 0x%04X", ethertype_);
  else snprintf(setting, sizeof setting, "UDP port %u", udp_port_);
  if (left >= 12)
    snprintf(out, cap, "ccomm frames %s (version %u, sender id %u, config hash %08x) that this node cannot "
             "receive: it uses %s. Give every board the same transport=, ethertype and udp_port", what,
             frame[4], Be16(frame + 6), Be32(frame + 8), setting);
  else
    snprintf(out, cap, "ccomm frames %s that this node cannot receive: it uses %s (%s)", what, setting, mine);
}

uint32_t ForeignFrameWatch::Poll(uint64_t now_ns) {
  if (fd_ < 0 || now_ns < next_poll_ns_) return 0;
  next_poll_ns_ = now_ns + kPollEveryNs;
  // The kernel's count is exact even when the small buffer overflowed (tp_packets
  // includes tp_drops; reading resets both). Only a few frames are read, to say what.
  struct tpacket_stats st;
  socklen_t len = sizeof st;
  if (getsockopt(fd_, SOL_PACKET, PACKET_STATISTICS, &st, &len) != 0) return 0;
  uint8_t f[kSnap];
  char first[320] = "";
  for (uint32_t i = 0; i < kMaxReadPerPoll; ++i) {
    const ssize_t n = recv(fd_, f, sizeof f, MSG_DONTWAIT);
    if (n < 0) break;  // EAGAIN: nothing more
    if (!first[0] && n >= 14 + 4 && now_ns >= next_log_ns_) Describe(f, static_cast<size_t>(n), first, sizeof first);
  }
  unlogged_ += st.tp_packets;
  if (first[0]) {
    Log(LogLevel::kWarning, "%s (%llu such frames; counted in frames_foreign)", first,
        static_cast<unsigned long long>(unlogged_));
    unlogged_ = 0;
    next_log_ns_ = now_ns + kLogEveryNs;
  }
  return st.tp_packets;
}

void ForeignFrameWatch::Close() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
}

}  // namespace ccomm
