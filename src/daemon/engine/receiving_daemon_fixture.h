// SPDX-License-Identifier: Apache-2.0
// Test fixture of the receive-path tests (rx_rules_test, large_values_test): a real
// ccommd as node a (0) with its receive thread running, and a UDP socket bound to node
// b's (1) address that sends it hand-made frames over loopback.
#pragma once

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>
#include <thread>
#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "testing/test_config.h"
#include "wire/wire.h"

namespace ccomm {
namespace testing {

class ReceivingDaemonTest : public ::testing::Test {
 protected:
  // Starts ccommd for `signals` (node 0 = a, the daemon; node 1 = b, the test) over UDP on
  // a free port, segments under a prefix of their own (`tag`).
  void StartDaemon(const char* tag, const std::vector<SignalConfig>& signals) {
    setenv("CCOMM_SHM_PREFIX", UniquePrefix(tag).c_str(), 1);
    cfg_ = TwoNodeConfig(signals);
    cfg_.nodes[0].transport = cfg_.nodes[1].transport = TransportKind::kUdp;
    cfg_.network.udp_port = FreeUdpPort();
    tx_ = BoundSocket(cfg_.nodes[1].ip.c_str());
    to_.sin_family = AF_INET;
    to_.sin_port = htons(cfg_.network.udp_port);
    inet_pton(AF_INET, cfg_.nodes[0].ip.c_str(), &to_.sin_addr);
    DaemonOptions opt = opt_;
    opt.no_realtime = true;
    opt.recv_timeout_ms = 20;
    std::string err;
    ASSERT_EQ(daemon_.Start(cfg_, 0, opt, &err), 0) << err;
    rx_ = std::thread([this] { daemon_.RunRx(); });
  }
  void TearDown() override {
    if (rx_.joinable()) {
      daemon_.RequestStop();
      rx_.join();
    }
    daemon_.Shutdown();
    if (tx_ >= 0) close(tx_);
    platform::ShmUnlink(store::SegmentName("a").c_str());
  }
  // The header of a data frame from node 1 (the peer, `tx_`) to node 0, sent at `send_ns`
  // on the peer's clock.
  wire::FrameHeader PeerFrameHeader(uint32_t seq, uint64_t send_ns) const {
    wire::FrameHeader h;
    h.sender = 1;
    h.dest = 0;
    h.config_hash = cfg_.hash;
    h.seq = seq;
    h.send_time_ns = send_ns;
    return h;
  }
  // A UDP socket bound to `ip` (any port): frames from it come from that node's address.
  static int BoundSocket(const char* ip) {
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in src = {};
    src.sin_family = AF_INET;
    inet_pton(AF_INET, ip, &src.sin_addr);
    EXPECT_EQ(bind(fd, reinterpret_cast<const sockaddr*>(&src), sizeof src), 0);
    return fd;
  }

  SystemConfig cfg_;
  DaemonOptions opt_;  // a test may set what StartDaemon passes on (realtime and recv timeout are the fixture's)
  Daemon daemon_;
  std::thread rx_;
  int tx_ = -1;
  struct sockaddr_in to_ = {};
};

}  // namespace testing
}  // namespace ccomm
