// SPDX-License-Identifier: Apache-2.0
// One image for every board: which node a board is, from --node/$CCOMM_NODE, the
// hostname, or its interfaces' MAC or IP; clear errors when none or several match.
#include "daemon/net/local_interface_test_util.h"
#include "daemon/net/node_identity.h"

#include <gtest/gtest.h>

#include "testing/test_config.h"

namespace ccomm {
namespace {

SystemConfig Cfg() {
  SystemConfig cfg = testing::TwoNodeConfig({});
  cfg.nodes[0].ip = "10.42.0.1";
  cfg.nodes[1].ip = "10.42.0.2";
  cfg.nodes[1].has_mac = true;
  const uint8_t mac[6] = {0x52, 0x54, 0, 0x12, 0x34, 0x02};
  memcpy(cfg.nodes[1].mac, mac, 6);
  return cfg;
}

TEST(NodeIdentity, ExplicitNameWinsAndMustExist) {
  std::string how, err;
  EXPECT_EQ(IdentifyNode(Cfg(), "b", "--node", "a", {}, &how, &err), 1);
  EXPECT_EQ(how, "--node");
  EXPECT_EQ(IdentifyNode(Cfg(), "x", "$CCOMM_NODE", "a", {}, &how, &err), -1);
  EXPECT_NE(err.find("no node 'x' ($CCOMM_NODE; nodes: a, b)"), std::string::npos) << err;
}

TEST(NodeIdentity, HostnameThenMacThenIp) {
  std::string how, err;
  const uint8_t mac_b[6] = {0x52, 0x54, 0, 0x12, 0x34, 0x02}, other[6] = {2, 0, 0, 0, 0, 9};
  EXPECT_EQ(IdentifyNode(Cfg(), "", "", "a", {If("eth0", {"10.42.0.2"}, mac_b)}, &how, &err), 0);
  EXPECT_EQ(how, "the hostname");
  EXPECT_EQ(IdentifyNode(Cfg(), "", "", "board", {If("eth0", {}, mac_b)}, &how, &err), 1);
  EXPECT_NE(how.find("b by mac 52:54:00:12:34:02 on eth0"), std::string::npos) << how;
  EXPECT_EQ(IdentifyNode(Cfg(), "", "", "board", {If("eth0", {"10.42.0.1"}, other)}, &how, &err), 0);
  EXPECT_NE(how.find("a by ip 10.42.0.1 on eth0"), std::string::npos) << how;
}

TEST(NodeIdentity, NoneOrSeveralAreClearErrors) {
  std::string how, err;
  const uint8_t other[6] = {2, 0, 0, 0, 0, 9};
  EXPECT_EQ(IdentifyNode(Cfg(), "", "", "board", {If("eth0", {"10.0.0.5"}, other)}, &how, &err), -1);
  EXPECT_NE(err.find("no node of test.xml is this board"), std::string::npos) << err;
  EXPECT_NE(err.find("eth0 02:00:00:00:00:09 10.0.0.5"), std::string::npos) << err;
  EXPECT_EQ(IdentifyNode(Cfg(), "", "", "board", {If("eth0", {"10.42.0.1", "10.42.0.2"}, other)}, &how, &err), -1);
  EXPECT_NE(err.find("matches several nodes"), std::string::npos) << err;
}

}  // namespace
}  // namespace ccomm
