// SPDX-License-Identifier: Apache-2.0
// The transports a Linux build registers (transport.h): each found by its kind, under the
// name signals.xml gives it, and the table each opens carries the same name.
#include <gtest/gtest.h>

#include <string.h>

#include "config/config.h"
#include "daemon/net/transport.h"

namespace ccomm {
namespace {

TEST(TransportRegistry, LinuxHasRawAndUdpByKindAndName) {
  const TransportProvider* raw = FindTransport(TransportKind::kRaw);
  const TransportProvider* udp = FindTransport(TransportKind::kUdp);
  ASSERT_NE(raw, nullptr);
  ASSERT_NE(udp, nullptr);
  EXPECT_STREQ(raw->name, "raw");
  EXPECT_STREQ(udp->name, "udp");
  size_t n = 0;
  for (const TransportProvider* const* p = kTransports; *p; ++p) ++n;
  EXPECT_EQ(n, 2u);
}

TEST(TransportRegistry, OpenedTableCarriesTheProvidersName) {
  // UDP on loopback needs no privileges: open it, compare, close.
  SystemConfig cfg;
  cfg.network.udp_port = 0;  // any free port
  NodeConfig self;
  self.name = "a";
  self.ip = "127.0.0.1";
  self.transport = TransportKind::kUdp;
  Transport t;
  std::string error;
  ASSERT_EQ(FindTransport(TransportKind::kUdp)->open(cfg.network, self, 10, &t, &error), 0) << error;
  ASSERT_NE(t.ops, nullptr);
  EXPECT_STREQ(t.ops->name, "udp");
  t.Close();
  EXPECT_EQ(t.ops, nullptr);
}

}  // namespace
}  // namespace ccomm
