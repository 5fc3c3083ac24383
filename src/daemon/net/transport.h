// SPDX-License-Identifier: Apache-2.0
// One transport per file behind a short function table (LCM style), each registered by
// name as a provider: raw Ethernet (net/posix/transport_raw.cpp; Linux only) and UDP
// (net/posix/transport_udp.cpp, net/windows/transport_udp.cpp). The platform's list of
// providers is net/PLATFORM/transports.cpp. Each keeps its own state (socket, interface,
// port) behind an opaque pointer; ccommd sees only the table. ccommd opens one at
// start-up; send and recv are the only calls on its real-time paths and never allocate.
// Each transport file is the platform layer of its transport (sockets). The configuration
// is only named here (forward declarations): a transport's unit includes it.
#pragma once

#include <errno.h>
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace ccomm {

struct NetworkConfig;
struct NodeConfig;
enum class TransportKind : uint8_t;  // config/config.h
struct TxtimeProbe;                  // txtime_probe.h

/// Where a frame goes (or came from). Raw: mac; UDP: ipv4 + port (network order).
struct PeerAddress {
  uint8_t mac[6] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
  uint32_t ipv4 = 0;
  uint16_t port = 0;
};

struct Transport;

struct TransportOps {
  const char* name;
  /// Sends one frame; 0 or -errno. Never blocks for long (socket send buffer).
  int (*send)(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len);
  /// Waits up to the transport's receive timeout for one frame. Returns its length,
  /// 0 on timeout, -EMSGSIZE for a frame larger than `cap`, -ENODATA for an empty one,
  /// or another -errno. `from` is filled when a frame is returned.
  ssize_t (*recv)(Transport* t, uint8_t* buf, size_t cap, PeerAddress* from);
  /// Frames the kernel dropped before ccommd read them (cumulative); 0 or -errno.
  int (*socket_drops)(Transport* t, uint32_t* drops);
  /// Multicast fan-out: receive the groups `groups[0..n)` (addresses from GroupAddressFor)
  /// and, where the transport can, nothing of other ccomm groups (raw: a socket filter,
  /// so frames of producers this node does not exchange with never wake ccommd). Start-up
  /// only; 0 or -errno with a message in `error`.
  int (*join_groups)(Transport* t, const PeerAddress* groups, size_t n, std::string* error);
  /// Closes the socket and frees the state.
  void (*close)(Transport* t);
  // send on the cycle (send_cycle.h): nullptr where the transport has no launch times.
  /// Start-up: SO_TXTIME on the socket and the interface's qdiscs, into `probe`.
  void (*txtime_setup)(Transport* t, TxtimeProbe* probe, std::string* detail);
  /// Sends one frame with launch time `launch_tai_ns` (CLOCK_TAI); 0 or -errno.
  int (*send_at)(Transport* t, const PeerAddress& to, const uint8_t* frame, size_t len, uint64_t launch_tai_ns);
  /// Frames the ETF qdisc reported dropped since the last call (supervision tick).
  uint32_t (*txtime_drops)(Transport* t);
};

struct Transport {
  const TransportOps* ops = nullptr;
  void* state = nullptr;  // the transport's own, allocated at open (start-up)
  // send on the cycle: with launch times on, every frame needs one (ETF drops frames
  // without): Send() gives it "now + txtime_asap_ns". 0: launch times off.
  uint64_t txtime_asap_ns = 0;

  int Send(const PeerAddress& to, const uint8_t* f, size_t n) { return ops->send(this, to, f, n); }
  int SendAt(const PeerAddress& to, const uint8_t* f, size_t n, uint64_t launch_tai_ns) {  // send on the cycle
    return ops->send_at(this, to, f, n, launch_tai_ns);
  }
  ssize_t Recv(uint8_t* b, size_t cap, PeerAddress* from) { return ops->recv(this, b, cap, from); }
  int SocketDrops(uint32_t* drops) { return ops ? ops->socket_drops(this, drops) : -EBADF; }
  int JoinGroups(const PeerAddress* g, size_t n, std::string* error) { return ops->join_groups(this, g, n, error); }
  void Close() {
    if (ops) ops->close(this);
    ops = nullptr;
    state = nullptr;
  }
};

/// A transport by name (LCM's lcm_create picks its provider by name): what opens it.
struct TransportProvider {
  const char* name;    // as <node transport="..."> spells it
  TransportKind kind;  // the parsed form
  /// Opens the transport `self` is configured for. `recv_timeout_ms` bounds Recv so the
  /// receive thread can notice shutdown. Returns 0, or -errno with a message in `error`
  /// that says what to do (e.g. missing CAP_NET_RAW). With fanout="multicast" the UDP
  /// socket binds to any address (to receive groups).
  int (*open)(const NetworkConfig& net, const NodeConfig& self, int recv_timeout_ms, Transport* out,
              std::string* error);
};

/// The providers this build has, ended by nullptr (net/PLATFORM/transports.cpp).
extern const TransportProvider* const kTransports[];
/// The provider of `kind`, or nullptr where this build has none (raw Ethernet on
/// Windows: then RawEthernetUnavailable says what to do).
const TransportProvider* FindTransport(TransportKind kind);
/// "node 'X' uses transport=\"raw\": raw Ethernet is Linux-only; ..." (and what to do).
std::string RawEthernetUnavailable(const NodeConfig& self);

/// Multicast fan-out: the group node `node_id` sends to (docs/protocol.md, "Fan-out"):
/// raw MAC 03:63:63:6d:00:ID, UDP multicast_base + ID on udp_port.
PeerAddress GroupAddressFor(const NetworkConfig& net, uint32_t node_id, TransportKind kind);
/// The group every node joins with fanout="multicast" and summaries on (summary_ms > 0):
/// node summaries go there, so `ccomm stats --all` sees every node from any board, not
/// only those it exchanges signals with (raw MAC 03:63:63:6d:00:40, UDP multicast_base + 64).
constexpr uint32_t kSummaryGroup = 64;  // = kMaxNodes (static_assert in transport_address.cpp)
/// First four bytes of every group MAC (a locally administered multicast prefix, "ccm").
constexpr uint8_t kGroupMacPrefix[4] = {0x03, 0x63, 0x63, 0x6d};

/// Address of `peer` for `t`'s kind (broadcast MAC when the peer has none; its
/// multicast group or unicast IP for UDP). False if the peer cannot be reached.
bool PeerAddressFor(const NetworkConfig& net, const NodeConfig& peer, TransportKind kind,
                    PeerAddress* out);

}  // namespace ccomm
