// SPDX-License-Identifier: Apache-2.0
// <ros2> in signals.xml (ros2_section.cpp): values, defaults, and every error with its line.
#include <gtest/gtest.h>

#include <string>

#include "config/config.h"

namespace ccomm {
namespace {

std::string Doc(const std::string& ros2) {
  return "<ccomm version=\"1\">\n"                                                     // 1
         "  <node name=\"control\" interface=\"eth0\" ip=\"10.42.0.1\"/>\n"            // 2
         "  <node name=\"planner\" interface=\"eth0\" ip=\"10.42.0.2\"/>\n"            // 3
         "  <signal name=\"pos\" type=\"double\" producer=\"control\" consumers=\"planner\"/>\n"
         "  <signal name=\"sp\" type=\"double\" count=\"3\" producer=\"planner\" consumers=\"control\"/>\n"
         "  <signal name=\"a.b\" type=\"double\" producer=\"control\" consumers=\"planner\"/>\n"
         "  <signal name=\"loc\" type=\"double\" producer=\"control\"/>\n"
         "  " + ros2 + "\n"                                                            // 8
         "</ccomm>\n";
}

TEST(Ros2Section, ValuesAndDefaults) {
  SystemConfig cfg;
  std::string err;
  ASSERT_TRUE(ParseConfig(Doc("<ros2 node=\"planner\" namespace=\"/robot1/arm/\" domain=\"7\" "
                              "publish=\"pos\" subscribe=\"sp\"/>"), "t.xml", &cfg, &err)) << err;
  ASSERT_EQ(cfg.ros2.size(), 1u);
  const Ros2Config& r = cfg.ros2[0];
  EXPECT_EQ(r.node, "planner");
  EXPECT_EQ(r.ros_namespace, "robot1/arm");
  EXPECT_TRUE(r.has_domain);
  EXPECT_EQ(r.domain, 7u);
  EXPECT_TRUE(r.publish_given);
  EXPECT_EQ(r.publish, std::vector<std::string>{"pos"});
  EXPECT_EQ(r.subscribe, std::vector<std::string>{"sp"});
  EXPECT_EQ(r.line, 8);

  SystemConfig plain;
  ASSERT_TRUE(ParseConfig(Doc("<ros2 node=\"planner\"/>"), "t.xml", &plain, &err)) << err;
  EXPECT_EQ(plain.ros2[0].ros_namespace, "ccomm");
  EXPECT_FALSE(plain.ros2[0].has_domain);
  EXPECT_FALSE(plain.ros2[0].publish_given);
  // Local policy: the section does not change the configuration hash.
  SystemConfig none;
  ASSERT_TRUE(ParseConfig(Doc(""), "t.xml", &none, &err)) << err;
  EXPECT_EQ(none.hash, cfg.hash);
}

void ExpectError(const std::string& ros2, const std::string& fragment) {
  SystemConfig cfg;
  std::string err;
  EXPECT_FALSE(ParseConfig(Doc(ros2), "t.xml", &cfg, &err)) << ros2;
  size_t at = err.find(fragment);
  ASSERT_NE(at, std::string::npos) << err;
  size_t bol = err.rfind('\n', at);
  bol = bol == std::string::npos ? 0 : bol + 1;
  EXPECT_EQ(err.compare(bol, 16, "t.xml:8: error: "), 0) << err;
}

TEST(Ros2Section, ErrorsNameTheLine) {
  ExpectError("<ros2/>", "<ros2> without node=");
  ExpectError("<ros2 node=\"nobody\"/>", "<ros2> for unknown node 'nobody'");
  ExpectError("<ros2 node=\"planner\" domain=\"233\"/>", "domain 233 out of range");
  ExpectError("<ros2 node=\"planner\" namespace=\"a//b\"/>", "namespace 'a//b' is not a ROS 2 name");
  ExpectError("<ros2 node=\"planner\" namespace=\"9a\"/>", "namespace '9a' is not a ROS 2 name");
  ExpectError("<ros2 node=\"planner\" publish=\"nosuch\"/>", "<ros2> publish: unknown signal 'nosuch'");
  ExpectError("<ros2 node=\"planner\" subscribe=\"pos\"/>", "signal 'pos' is produced by node 'control'");
  ExpectError("<ros2 node=\"planner\" publish=\"loc\"/>", "signal 'loc' is neither produced nor consumed on node 'planner'");
  ExpectError("<ros2 node=\"control\" publish=\"pos\" subscribe=\"pos\"/>", "in both publish and subscribe");
  ExpectError("<ros2 node=\"planner\" publish=\"a.b\"/>", "signal name 'a.b' is not a ROS 2 topic name token");
  ExpectError("<ros2 node=\"planner\" qos=\"x\"/>", "unknown attribute 'qos' on <ros2>");
  ExpectError("<ros2 node=\"planner\"><publish/></ros2>", "unknown element <publish> in <ros2>");
}

TEST(Ros2Section, OnePerNode) {
  SystemConfig cfg;
  std::string err;
  std::string two = "<ros2 node=\"planner\"/>\n  <ros2 node=\"planner\"/>";
  EXPECT_FALSE(ParseConfig(Doc(two), "t.xml", &cfg, &err));
  EXPECT_NE(err.find("t.xml:9: error: second <ros2> for node 'planner' (first at line 8)"), std::string::npos) << err;
}

}  // namespace
}  // namespace ccomm
