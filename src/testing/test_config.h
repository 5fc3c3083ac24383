// SPDX-License-Identifier: Apache-2.0
// Builds small SystemConfigs in code for store/client/daemon tests (no XML needed).
#pragma once

#include <string>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include "config/config.h"

namespace ccomm {
namespace testing {

inline SignalConfig MakeSignal(const std::string& name, ValueType type, uint32_t count, SignalKind kind,
                               uint32_t producer, std::vector<uint32_t> consumers) {
  SignalConfig s;
  s.name = name;
  s.type = type;
  s.count = count;
  s.kind = kind;
  s.producer = producer;
  s.consumers = std::move(consumers);
  return s;
}

/// Two nodes "a" (0) and "b" (1) on loopback; signals chosen by the test. The model
/// itself, built without XML: the store's and client's tests sit below the parser (the
/// tests' two-node document in text is testing/config_document.h's TwoNodeXml).
inline SystemConfig TwoNodeConfig(std::vector<SignalConfig> signals) {
  SystemConfig cfg;
  cfg.path = "test.xml";
  NodeConfig a, b;
  a.name = "a";
  a.interface = "lo";
  a.ip = "127.0.0.1";
  b.name = "b";
  b.interface = "lo";
  b.ip = "127.0.0.2";
  cfg.nodes = {a, b};
  cfg.signals = std::move(signals);
  cfg.hash = 0x1234u + static_cast<uint32_t>(cfg.signals.size());
  return cfg;
}

/// The pair most tests start from: "pos" (double, produced by a, consumed by b) and "sp"
/// (`sp_count` doubles, produced by b, consumed by a), in that order.
inline std::vector<SignalConfig> PosAndSetpoint(uint32_t sp_count = 1) {
  return {MakeSignal("pos", ValueType::kDouble, 1, SignalKind::kState, 0, {1}),
          MakeSignal("sp", ValueType::kDouble, sp_count, SignalKind::kState, 1, {0})};
}

/// A unique shm prefix per test process, so parallel test runs never share segments.
/// A UDP port free on loopback right now (tests bind ccommd to it next).
inline uint16_t FreeUdpPort() {
  int fd = socket(AF_INET, SOCK_DGRAM, 0);
  struct sockaddr_in sin = {};
  sin.sin_family = AF_INET;
  sin.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<struct sockaddr*>(&sin), sizeof sin);
  socklen_t sl = sizeof sin;
  getsockname(fd, reinterpret_cast<struct sockaddr*>(&sin), &sl);
  close(fd);
  return ntohs(sin.sin_port);
}

inline std::string UniquePrefix(const char* tag) {
  return "/ccomm-test-" + std::string(tag) + "-" + std::to_string(getpid()) + ".";
}

}  // namespace testing
}  // namespace ccomm
