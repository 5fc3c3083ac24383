// SPDX-License-Identifier: Apache-2.0
// <clock> in signals.xml (clock_section.cpp): values, defaults, and every error with its line.
#include <gtest/gtest.h>

#include <string>

#include "config/config.h"
#include "testing/config_document.h"

namespace ccomm {
namespace {

std::string Doc(const std::string& clock) { return testing::TwoNodeDocument(clock); }  // <clock> on line 5

TEST(ClockSection, ValuesAndDefaults) {
  SystemConfig cfg;
  std::string err;
  ASSERT_TRUE(ParseConfig(Doc("<clock domain=\"24\" grandmaster=\"control, planner\" timestamping=\"hardware\" "
                              "sync_interval_log=\"-4\" socket=\"/run/ptp4l-ccomm\"/>"), "t.xml", &cfg, &err)) << err;
  const ClockConfig& c = cfg.clock;
  EXPECT_TRUE(c.present);
  EXPECT_EQ(c.domain, 24u);
  EXPECT_EQ(c.grandmasters, (std::vector<std::string>{"control", "planner"}));
  EXPECT_TRUE(c.hardware);
  EXPECT_EQ(c.sync_interval_log, -4);
  EXPECT_EQ(c.socket, "/run/ptp4l-ccomm");
  EXPECT_EQ(c.line, 5);

  SystemConfig plain;
  ASSERT_TRUE(ParseConfig(Doc("<clock grandmaster=\"planner\"/>"), "t.xml", &plain, &err)) << err;
  EXPECT_EQ(plain.clock.domain, 0u);
  EXPECT_FALSE(plain.clock.hardware);
  EXPECT_EQ(plain.clock.sync_interval_log, -3);
  EXPECT_EQ(plain.clock.socket, "/var/run/ptp4l");
  // Local policy: the section does not change the configuration hash.
  SystemConfig none;
  ASSERT_TRUE(ParseConfig(Doc(""), "t.xml", &none, &err)) << err;
  EXPECT_FALSE(none.clock.present);
  EXPECT_EQ(none.hash, cfg.hash);
}

void ExpectError(const std::string& clock, const std::string& fragment) {
  SystemConfig cfg;
  std::string err;
  EXPECT_FALSE(ParseConfig(Doc(clock), "t.xml", &cfg, &err)) << clock;
  size_t at = err.find(fragment);
  ASSERT_NE(at, std::string::npos) << err;
  size_t bol = err.rfind('\n', at);
  bol = bol == std::string::npos ? 0 : bol + 1;
  EXPECT_EQ(err.compare(bol, 16, "t.xml:5: error: "), 0) << err;
}

TEST(ClockSection, ErrorsNameTheLine) {
  ExpectError("<clock/>", "<clock> without grandmaster=");
  ExpectError("<clock grandmaster=\"nobody\"/>", "<clock> grandmaster: unknown node 'nobody'");
  ExpectError("<clock grandmaster=\"control, control\"/>", "node 'control' given twice");
  ExpectError("<clock grandmaster=\"control,,planner\"/>", "empty name in grandmaster");
  ExpectError("<clock grandmaster=\"control\" domain=\"128\"/>", "domain 128 out of range");
  ExpectError("<clock grandmaster=\"control\" timestamping=\"gps\"/>", "timestamping 'gps' is not 'software' or 'hardware'");
  ExpectError("<clock grandmaster=\"control\" sync_interval_log=\"5\"/>", "sync_interval_log 5 out of range");
  ExpectError("<clock grandmaster=\"control\" socket=\"ptp4l\"/>", "socket 'ptp4l' is not an absolute path");
  ExpectError("<clock grandmaster=\"control\" priority=\"1\"/>", "unknown attribute 'priority' on <clock>");
  ExpectError("<clock grandmaster=\"control\"><port/></clock>", "unknown element <port> in <clock>");
}

TEST(ClockSection, AtMostOne) {
  SystemConfig cfg;
  std::string err;
  EXPECT_FALSE(ParseConfig(Doc("<clock grandmaster=\"control\"/>\n  <clock grandmaster=\"planner\"/>"), "t.xml",
                           &cfg, &err));
  EXPECT_NE(err.find("t.xml:6: error: second <clock> (first at line 5)"), std::string::npos) << err;
}

}  // namespace
}  // namespace ccomm
