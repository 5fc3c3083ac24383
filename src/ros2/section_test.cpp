// SPDX-License-Identifier: Apache-2.0
// <ros2> in signals.xml as the bridge reads it (section.cpp): values, defaults, and every
// error with its line; the core parser passes the section on without knowing it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/public/outline.h"
#include "ros2/section.h"
#include "testing/config_document.h"

namespace ccomm_ros2 {
namespace {

// <ros2> on line 8, after the signals it maps.
std::string Doc(const std::string& ros2) {
  return ccomm::testing::TwoNodeDocument(
      ros2, "  <signal name=\"sp\" type=\"double\" count=\"3\" producer=\"planner\" consumers=\"control\"/>\n"
            "  <signal name=\"a.b\" type=\"double\" producer=\"control\" consumers=\"planner\"/>\n"
            "  <signal name=\"loc\" type=\"double\" producer=\"control\"/>\n");
}

// The file through the core parser, then its <ros2> sections through the bridge's.
bool Read(const std::string& ros2, std::vector<Ros2Section>* out, std::string* err) {
  ccomm::ConfigOutline cfg;
  if (!ccomm::ParseConfigOutline(Doc(ros2), "t.xml", &cfg, err)) {
    ADD_FAILURE() << "the core parser refused " << ros2 << ": " << *err;
    return false;
  }
  return ReadRos2Sections(cfg, out, err);
}

TEST(Ros2Section, ValuesAndDefaults) {
  std::vector<Ros2Section> s;
  std::string err;
  ASSERT_TRUE(Read("<ros2 node=\"planner\" namespace=\"/robot1/arm/\" domain=\"7\" "
                   "publish=\"pos\" subscribe=\"sp\"/>", &s, &err)) << err;
  ASSERT_EQ(s.size(), 1u);
  const Ros2Section& r = s[0];
  EXPECT_EQ(r.node, "planner");
  EXPECT_EQ(r.ros_namespace, "robot1/arm");
  EXPECT_TRUE(r.has_domain);
  EXPECT_EQ(r.domain, 7u);
  EXPECT_TRUE(r.publish_given);
  EXPECT_EQ(r.publish, std::vector<std::string>{"pos"});
  EXPECT_EQ(r.subscribe, std::vector<std::string>{"sp"});
  EXPECT_EQ(r.line, 8);

  std::vector<Ros2Section> plain;
  ASSERT_TRUE(Read("<ros2 node=\"planner\"/>", &plain, &err)) << err;
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_EQ(plain[0].ros_namespace, "ccomm");
  EXPECT_FALSE(plain[0].has_domain);
  EXPECT_FALSE(plain[0].publish_given);
  std::vector<Ros2Section> none;
  ASSERT_TRUE(Read("", &none, &err)) << err;
  EXPECT_TRUE(none.empty());
}

void ExpectError(const std::string& ros2, const std::string& fragment, int line = 8) {
  std::vector<Ros2Section> s;
  std::string err;
  EXPECT_FALSE(Read(ros2, &s, &err)) << ros2;
  size_t at = err.find(fragment);
  ASSERT_NE(at, std::string::npos) << err;
  size_t bol = err.rfind('\n', at);
  bol = bol == std::string::npos ? 0 : bol + 1;
  const std::string where = "t.xml:" + std::to_string(line) + ": error: ";
  EXPECT_EQ(err.compare(bol, where.size(), where), 0) << err;
}

TEST(Ros2Section, ErrorsNameTheLine) {
  ExpectError("<ros2/>", "<ros2> without node=");
  // Found by fuzz_ros2_section: an empty node= was accepted and skipped the cross-check.
  ExpectError("<ros2 node=\"\"/>", "<ros2> with an empty node=");
  ExpectError("<ros2 node=\"nobody\"/>", "<ros2> for unknown node 'nobody'");
  ExpectError("<ros2 node=\"planner\" domain=\"233\"/>", "domain 233 out of range (expected 0..232)");
  ExpectError("<ros2 node=\"planner\" domain=\"99999999999999999999\"/>", "out of range");
  ExpectError("<ros2 node=\"planner\" domain=\"7x\"/>", "invalid domain '7x'");
  ExpectError("<ros2 node=\"planner\" namespace=\"a//b\"/>", "namespace 'a//b' is not a ROS 2 name");
  ExpectError("<ros2 node=\"planner\" namespace=\"9a\"/>", "namespace '9a' is not a ROS 2 name");
  ExpectError("<ros2 node=\"planner\" publish=\"nosuch\"/>", "<ros2> publish: unknown signal 'nosuch'");
  ExpectError("<ros2 node=\"planner\" publish=\"pos,,sp\"/>", "empty name in publish 'pos,,sp'");
  ExpectError("<ros2 node=\"planner\" subscribe=\"pos\"/>", "signal 'pos' is produced by node 'control'");
  ExpectError("<ros2 node=\"planner\" publish=\"loc\"/>", "signal 'loc' is neither produced nor consumed on node 'planner'");
  ExpectError("<ros2 node=\"control\" publish=\"pos\" subscribe=\"pos\"/>", "in both publish and subscribe");
  ExpectError("<ros2 node=\"planner\" publish=\"a.b\"/>", "signal name 'a.b' is not a ROS 2 topic name token");
  ExpectError("<ros2 node=\"planner\" qos=\"x\"/>", "unknown attribute 'qos' on <ros2>");
  ExpectError("<ros2 node=\"planner\">\n<publish/></ros2>", "unknown element <publish> in <ros2>", 9);
}

TEST(Ros2Section, OnePerNode) {
  std::vector<Ros2Section> s;
  std::string err;
  EXPECT_FALSE(Read("<ros2 node=\"planner\"/>\n  <ros2 node=\"planner\"/>", &s, &err));
  EXPECT_NE(err.find("t.xml:9: error: second <ros2> for node 'planner' (first at line 8)"), std::string::npos) << err;
}

TEST(Ros2Section, Names) {
  EXPECT_TRUE(IsRosToken("joint_pos2"));
  EXPECT_FALSE(IsRosToken(""));
  EXPECT_FALSE(IsRosToken("2x"));
  EXPECT_FALSE(IsRosToken("a.b"));
  EXPECT_TRUE(IsRosNamespace(""));
  EXPECT_TRUE(IsRosNamespace("robot1/arm"));
  EXPECT_FALSE(IsRosNamespace("robot1//arm"));
  EXPECT_FALSE(IsRosNamespace("robot1/"));
}

}  // namespace
}  // namespace ccomm_ros2
