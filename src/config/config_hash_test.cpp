// SPDX-License-Identifier: Apache-2.0
// Tests of the config hash (canonical form of docs/config.md) and fan-out/monitor expansion.
#include "config/config.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "config/config_test_util.h"

namespace ccomm {
namespace {

// ------------------------------------------------------------------------- hash

const char* kHashBase = R"(<ccomm version="1">
  <network ethertype="0x88B5" udp_port="47800"/>
  <node name="client" interface="eth0"/>
  <node name="server" interface="eth0"/>
  <node name="logger" interface="eth0"/>
  <node name="spare" interface="eth0"/>
  <signal name="value" type="double" producer="client" consumers="server,logger"/>
  <signal name="cmd" type="int32" count="4" kind="event" producer="server" consumers="client"/>
</ccomm>
)";

uint32_t HashOf(const std::string& xml) { return MustParse(xml).hash; }

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  size_t p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  if (p != std::string::npos) s.replace(p, from.size(), to);
  return s;
}

TEST(Hash, MatchesTheDocumentedCanonicalForm) {
  // Computed independently (Python) from the canonical form in docs/config.md:
  //   ccomm-config 1\nnetwork 34997 47800\nnode client\nnode server\nnode logger\n
  //   node spare\n
  //   signal value double 1 state client server,logger\n
  //   signal cmd int32 4 event server client\n
  EXPECT_EQ(HashOf(kHashBase), 0x35465836u);
}

TEST(Hash, IgnoresLayoutCommentsAndLocalPolicy) {
  const uint32_t base = HashOf(kHashBase);
  const std::string b = kHashBase;
  // Whitespace, comments, attribute order, quoting style, consumer order.
  EXPECT_EQ(HashOf("<!-- c -->\n" + Replace(b, "<node name=\"client\" interface=\"eth0\"/>",
                                            "<node   interface='eth0'\n\n name='client' >"
                                            "<!-- x --></node>")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "consumers=\"server,logger\"", "consumers=\" logger , server\"")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "consumers=\"server,logger\"", "consumers=\"logger\tserver\"")),
            base);
  // Local policy: staleness, safe values, periods, realtime, addresses, transport.
  EXPECT_EQ(HashOf(Replace(b, "consumers=\"server,logger\"",
                           "consumers=\"server,logger\" stale_after_ms=\"20\" safe_value=\"1\" "
                           "period_ms=\"2\"")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "<node name=\"server\" interface=\"eth0\"/>",
                           "<node name=\"server\" interface=\"eth1\" ip=\"10.0.0.2\" "
                           "mac=\"02:00:00:00:00:02\" history=\"1024\"><realtime priority=\"90\"/></node>")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "<network ethertype=\"0x88B5\" udp_port=\"47800\"/>",
                           "<network ethertype=\"34997\" udp_port=\"47800\" heartbeat_ms=\"10\" "
                           "peer_timeout_ms=\"50\"/>")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "kind=\"event\"", "kind=\"event\" queue_depth=\"1024\"")), base);
}

TEST(Hash, ChangesWithWhatBothEndsMustAgreeOn) {
  const uint32_t base = HashOf(kHashBase);
  const std::string b = kHashBase;
  const std::vector<std::pair<std::string, std::string>> changes = {
      {"type=\"double\"", "type=\"float\""},
      {"type=\"int32\"", "type=\"uint32\""},
      {"count=\"4\"", "count=\"5\""},
      {"kind=\"event\"", "kind=\"state\""},
      {"name=\"value\"", "name=\"value2\""},
      {"producer=\"client\"", "producer=\"spare\""},
      {"consumers=\"server,logger\"", "consumers=\"server\""},
      {"consumers=\"client\"", "consumers=\"client,logger\""},
      {"<node name=\"logger\"", "<node name=\"logger2\""},
      {"udp_port=\"47800\"", "udp_port=\"47801\""},
      {"ethertype=\"0x88B5\"", "ethertype=\"0x88B6\""},
  };
  for (const auto& [from, to] : changes) {
    std::string xml = Replace(b, from, to);
    if (to.find("logger2") != std::string::npos)
      xml = Replace(xml, "consumers=\"server,logger\"", "consumers=\"server,logger2\"");
    EXPECT_NE(HashOf(xml), base) << from << " -> " << to;
  }
  // Node order and signal order define the ids.
  std::string swapped_nodes =
      Replace(b, "<node name=\"client\" interface=\"eth0\"/>\n  <node name=\"server\" "
                 "interface=\"eth0\"/>",
                 "<node name=\"server\" interface=\"eth0\"/>\n  <node name=\"client\" "
                 "interface=\"eth0\"/>");
  EXPECT_NE(HashOf(swapped_nodes), base);
  const std::string sig1 =
      "<signal name=\"value\" type=\"double\" producer=\"client\" consumers=\"server,logger\"/>";
  const std::string sig2 =
      "<signal name=\"cmd\" type=\"int32\" count=\"4\" kind=\"event\" producer=\"server\" "
      "consumers=\"client\"/>";
  std::string swapped_signals = Replace(Replace(b, sig1, "@1"), sig2, sig1);
  swapped_signals = Replace(swapped_signals, "@1", sig2);
  EXPECT_NE(HashOf(swapped_signals), base);
}

// ------------------------------------------------------------- fan-out, monitors

TEST(Fanout, MonitorAndMulticastAreHashedAsDocumented) {
  // docs/config.md: the monitor is expanded into the consumer lists; fanout="multicast"
  // adds one line. Computed independently (Python) from that canonical form:
  //   ccomm-config 1\nnetwork 34997 47800\nfanout multicast 239.255.67.0\n
  //   node client\nnode server\nnode logger\nnode spare\n
  //   signal value double 1 state client server,logger,spare\n
  //   signal cmd int32 4 event server client,spare\n
  const std::string x = Replace(Replace(kHashBase, "udp_port=\"47800\"/>", "udp_port=\"47800\" fanout=\"multicast\"/>"),
                                "<node name=\"spare\" interface=\"eth0\"/>",
                                "<node name=\"spare\" interface=\"eth0\" monitor=\"*\"/>");
  SystemConfig cfg = MustParse(x);
  EXPECT_EQ(cfg.network.fanout, Fanout::kMulticast);
  EXPECT_EQ(cfg.signals[0].consumers, (std::vector<uint32_t>{1, 2, 3}));
  EXPECT_EQ(cfg.signals[1].consumers, (std::vector<uint32_t>{0, 3}));
  EXPECT_EQ(cfg.hash, 0xbbe8f4cau);
  // The default (unicast, no monitor) keeps the hash every existing file has.
  EXPECT_EQ(HashOf(Replace(kHashBase, "udp_port=\"47800\"/>", "udp_port=\"47800\" fanout=\"unicast\"/>")), 0x35465836u);
}

TEST(Fanout, MonitorPatternsSelectSignalsAndNeverTheirOwn) {
  SystemConfig cfg = MustParse(TwoNodes(
      "<node name=\"mon\" interface=\"eth0\" monitor=\"arm_*, cam_?\"/>\n"
      "<signal name=\"arm_q\" type=\"double\" producer=\"a\"/>\n"
      "<signal name=\"cam_1\" type=\"double\" producer=\"b\" consumers=\"mon\"/>\n"
      "<signal name=\"cam_10\" type=\"double\" producer=\"a\"/>\n"
      "<signal name=\"arm_mon\" type=\"double\" producer=\"mon\" consumers=\"a\"/>\n"));
  ASSERT_EQ(cfg.nodes[2].monitor, (std::vector<std::string>{"arm_*", "cam_?"}));
  EXPECT_EQ(cfg.signals[0].consumers, (std::vector<uint32_t>{2}));     // matched
  EXPECT_EQ(cfg.signals[1].consumers, (std::vector<uint32_t>{2}));     // listed once, not twice
  EXPECT_TRUE(cfg.signals[2].consumers.empty());                      // cam_? is one character
  EXPECT_EQ(cfg.signals[3].consumers, (std::vector<uint32_t>{0}));     // its own: not consumed
}

TEST(Fanout, BadValuesSayWhatIsExpected) {
  EXPECT_NE(MustFail(TwoNodes("<network fanout=\"broadcast\"/>")).find("unknown fanout 'broadcast' (expected unicast or multicast)"),
            std::string::npos);
  EXPECT_NE(MustFail(TwoNodes("<network multicast_base=\"10.0.0.0\"/>")).find("is not in 224.0.0.0/4"), std::string::npos);
  EXPECT_NE(MustFail(TwoNodes("<network multicast_base=\"239.1.1.250\"/>")).find("must leave room"), std::string::npos);
  EXPECT_NE(MustFail(TwoNodes("<node name=\"m\" interface=\"eth0\" monitor=\"a,,b\"/>")).find("empty pattern in monitor"),
            std::string::npos);
}

}  // namespace
}  // namespace ccomm
