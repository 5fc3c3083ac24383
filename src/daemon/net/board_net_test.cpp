// SPDX-License-Identifier: Apache-2.0
// ccommd --board-net's decision: which node (explicit, MAC before hostname), which
// interface, which address (ip= /24, DHCP without ip=), and when to wait for the driver.
#include "daemon/net/board_net.h"
#include "daemon/net/local_interface_test_util.h"

#include <gtest/gtest.h>

#include "testing/test_config.h"

namespace ccomm {
namespace {

const uint8_t kMacA[6] = {0x52, 0x54, 0, 0x42, 0, 0x01}, kMacB[6] = {0x52, 0x54, 0, 0x42, 0, 0x02};

SystemConfig Cfg() {
  SystemConfig cfg = testing::TwoNodeConfig({});
  cfg.nodes[0].name = "control";
  cfg.nodes[1].name = "planner";
  for (int i = 0; i < 2; ++i) {
    NodeConfig& n = cfg.nodes[static_cast<size_t>(i)];
    n.interface = "eth0";
    n.ip = i == 0 ? "10.42.0.1" : "10.42.0.2";
    n.has_mac = true;
    memcpy(n.mac, i == 0 ? kMacA : kMacB, 6);
    n.line = 10 + i;
  }
  return cfg;
}

TEST(BoardNet, KernelCmdlineNode) {
  EXPECT_EQ(KernelCmdlineNode("console=ttyAMA0 ccomm.node=planner root=/dev/vda\n"), "planner");
  EXPECT_EQ(KernelCmdlineNode("ccomm.node=a ccomm.node=b"), "b");  // the kernel's rule: the last wins
  EXPECT_EQ(KernelCmdlineNode("xccomm.node=a ccomm.nodes=b quiet"), "");
  EXPECT_EQ(KernelCmdlineNode(""), "");
}

TEST(BoardNet, MacBeforeHostname) {
  BoardNetPlan p;
  std::string err;
  // The image's hostname names the other board: the MAC decides.
  ASSERT_EQ(PlanBoardNet(Cfg(), "", "", "control", {If("eth0", {}, kMacB)}, false, &p, &err), 1) << err;
  EXPECT_EQ(p.node, 1);
  EXPECT_NE(p.how.find("planner by mac 52:54:00:42:00:02 on eth0"), std::string::npos) << p.how;
  EXPECT_EQ(p.interface, "eth0");
  EXPECT_EQ(p.address, "10.42.0.2/24");
}

TEST(BoardNet, ExplicitWinsAndHostnameIsTheFallback) {
  BoardNetPlan p;
  std::string err;
  ASSERT_EQ(PlanBoardNet(Cfg(), "control", "ccomm.node=", "x", {If("eth0", {}, kMacB)}, false, &p, &err), 1);
  EXPECT_EQ(p.node, 0);
  EXPECT_EQ(p.how, "ccomm.node=");
  const uint8_t other[6] = {2, 0, 0, 0, 0, 7};
  ASSERT_EQ(PlanBoardNet(Cfg(), "", "", "planner", {If("eth0", {}, other)}, false, &p, &err), 1);
  EXPECT_EQ(p.node, 1);
  EXPECT_EQ(p.how, "the hostname");
  EXPECT_EQ(PlanBoardNet(Cfg(), "nope", "ccomm.node=", "planner", {If("eth0", {}, kMacA)}, false, &p, &err), -1);
  EXPECT_NE(err.find("has no node 'nope' (ccomm.node=; nodes: control, planner)"), std::string::npos) << err;
}

TEST(BoardNet, WaitsForTheDriverThenSaysWhy) {
  BoardNetPlan p;
  std::string err;
  const uint8_t other[6] = {2, 0, 0, 0, 0, 7};
  // Nothing matches yet (eth0 not probed): wait, and on the last try say every way tried.
  EXPECT_EQ(PlanBoardNet(Cfg(), "", "", "localhost", {}, false, &p, &err), 0);
  EXPECT_EQ(PlanBoardNet(Cfg(), "", "", "localhost", {If("eth1", {}, other)}, true, &p, &err), -1);
  EXPECT_NE(err.find("the hostname 'localhost' names none"), std::string::npos) << err;
  EXPECT_NE(err.find("ccomm.node=NAME"), std::string::npos) << err;
  // Known node, interface missing: wait, then name the file's line and the interfaces.
  EXPECT_EQ(PlanBoardNet(Cfg(), "planner", "--node", "", {If("eth1", {}, other)}, false, &p, &err), 0);
  EXPECT_EQ(PlanBoardNet(Cfg(), "planner", "--node", "", {If("eth1", {}, other)}, true, &p, &err), -1);
  EXPECT_NE(err.find("test.xml:11: this board is node 'planner' (--node) but has no interface 'eth0' "
                     "(interfaces: eth1)"),
            std::string::npos)
      << err;
}

TEST(BoardNet, DhcpWithoutIpAndTheInterfaceOfTheMac) {
  SystemConfig cfg = Cfg();
  cfg.nodes[1].ip.clear();
  cfg.nodes[1].interface.clear();  // a UDP node: the interface is the one with its MAC
  cfg.nodes[1].transport = TransportKind::kUdp;
  BoardNetPlan p;
  std::string err;
  ASSERT_EQ(PlanBoardNet(cfg, "", "", "", {If("enp1s0", {}, kMacB)}, false, &p, &err), 1) << err;
  EXPECT_EQ(p.interface, "enp1s0");
  EXPECT_EQ(p.address, "");
  const std::string f = BoardNetNetworkFile(cfg, p);
  EXPECT_NE(f.find("[Match]\nName=enp1s0\n"), std::string::npos) << f;
  EXPECT_NE(f.find("DHCP=ipv4\n"), std::string::npos) << f;
  EXPECT_EQ(f.find("Address="), std::string::npos) << f;
  // Static: Address= with the /24, kept through a cable cut.
  ASSERT_EQ(PlanBoardNet(cfg, "control", "--node", "", {If("eth0", {}, kMacA)}, false, &p, &err), 1) << err;
  const std::string s = BoardNetNetworkFile(cfg, p);
  EXPECT_NE(s.find("Address=10.42.0.1/24\n"), std::string::npos) << s;
  EXPECT_NE(s.find("IgnoreCarrierLoss=yes\n"), std::string::npos) << s;
  EXPECT_EQ(s.find("DHCP="), std::string::npos) << s;
  // A node with neither interface= nor a MAC on this board: hostname only.
  cfg.nodes[1].has_mac = false;
  ASSERT_EQ(PlanBoardNet(cfg, "planner", "--node", "", {If("eth0", {}, kMacA)}, false, &p, &err), 1) << err;
  EXPECT_EQ(p.interface, "");
}

}  // namespace
}  // namespace ccomm
