// SPDX-License-Identifier: Apache-2.0
// Frames of ccomm this node cannot receive: another EtherType, the other transport, or
// another UDP port. A board set up differently from its peers would otherwise be
// silent: its frames never reach the transport's socket and the peer just never comes
// up. A second packet socket, filtered in the kernel to exactly such frames (it wakes
// for nothing else), is drained from the supervision tick: counted as frames_foreign
// and logged at most once per 10 s with what was seen.
#pragma once

#include <cstdint>

#include "config/config.h"

namespace ccomm {

class ForeignFrameWatch {
 public:
  ~ForeignFrameWatch() { Close(); }
  /// Opens the watch for `self` using transport `kind`. Needs CAP_NET_RAW: without it
  /// (an unprivileged UDP node) the watch stays off and this returns -EPERM.
  int Open(const NetworkConfig& net, const NodeConfig& self, TransportKind kind);
  /// Every 100 ms (call it from the supervision tick): how many foreign frames arrived
  /// since the last poll (the kernel's count, exact), and a log line describing one of
  /// them at most every 10 s. Never blocks; reads at most a few frames.
  uint32_t Poll(uint64_t now_ns);
  void Close();
  bool is_open() const { return fd_ >= 0; }

 private:
  void Describe(const uint8_t* f, size_t n, char* out, size_t cap) const;

  int fd_ = -1;
  TransportKind kind_ = TransportKind::kRaw;
  uint16_t ethertype_ = 0, udp_port_ = 0;
  uint64_t next_log_ns_ = 0, next_poll_ns_ = 0;
  uint64_t unlogged_ = 0;  // counted since the last log line
};

}  // namespace ccomm
