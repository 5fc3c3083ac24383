// SPDX-License-Identifier: Apache-2.0
// Extension sections (outline.h, extension_section.cpp): the core keeps them as element
// trees with lines and checks their structure only; their meaning is their owner's.
#include <gtest/gtest.h>

#include <string>

#include "config/config.h"
#include "config/config_json.h"
#include "config/public/outline.h"
#include "testing/config_document.h"

namespace ccomm {
namespace {

std::string Doc(const std::string& section) { return testing::TwoNodeDocument(section); }  // on line 5

TEST(ExtensionSection, KeptAsATreeWithLines) {
  ConfigOutline cfg;
  std::string err;
  ASSERT_TRUE(ParseConfigOutline(Doc("<ros2 node=\"planner\" publish=\"a &amp; b\"\n"
                                     "        anything=\"goes\">\n"
                                     "    <child x=\"1\"><grandchild/></child>\n"
                                     "  </ros2>"),
                                 "t.xml", &cfg, &err))
      << err;
  ASSERT_EQ(cfg.sections.size(), 1u);
  const SectionElement& s = cfg.sections[0];
  EXPECT_EQ(s.name, "ros2");
  EXPECT_EQ(s.line, 5);
  ASSERT_EQ(s.attributes.size(), 3u);
  ASSERT_NE(s.Find("publish"), nullptr);
  EXPECT_EQ(s.Find("publish")->value, "a & b");  // entities decoded
  ASSERT_NE(s.Find("anything"), nullptr);
  EXPECT_EQ(s.Find("anything")->line, 6);  // the core does not know the schema
  EXPECT_EQ(s.Find("nosuch"), nullptr);
  ASSERT_EQ(s.children.size(), 1u);
  EXPECT_EQ(s.children[0].name, "child");
  EXPECT_EQ(s.children[0].line, 7);
  ASSERT_EQ(s.children[0].children.size(), 1u);
  EXPECT_EQ(s.children[0].children[0].name, "grandchild");
  // The rest of the file, as the section's owner needs it.
  EXPECT_EQ(cfg.nodes, (std::vector<std::string>{"control", "planner"}));
  ASSERT_NE(cfg.FindSignal("pos"), nullptr);
  EXPECT_EQ(cfg.FindSignal("pos")->producer, "control");
  EXPECT_EQ(cfg.FindSignal("pos")->consumers, std::vector<std::string>{"planner"});
  EXPECT_TRUE(cfg.HasNode("planner"));
  EXPECT_FALSE(cfg.HasNode("nobody"));
}

TEST(ExtensionSection, NotHashedAndInTheJson) {
  SystemConfig with, without;
  std::string err;
  ASSERT_TRUE(ParseConfig(Doc("<ros2 node=\"planner\" domain=\"7\"/>"), "t.xml", &with, &err)) << err;
  ASSERT_TRUE(ParseConfig(Doc(""), "t.xml", &without, &err)) << err;
  EXPECT_EQ(with.hash, without.hash);  // local policy
  const std::string json = ConfigToJson(with);
  EXPECT_NE(json.find("\"sections\":[{\"owner\":\"ccomm-ros2\",\"name\":\"ros2\",\"line\":5,\"attributes\":{\"node\":\"planner\","
                      "\"domain\":\"7\"},\"children\":[]}]"),
            std::string::npos)
      << json;
}

void ExpectError(const std::string& section, const std::string& expected) {
  SystemConfig cfg;
  std::string err;
  EXPECT_FALSE(ParseConfig(Doc(section), "t.xml", &cfg, &err)) << section;
  EXPECT_NE(err.find(expected), std::string::npos) << err;
}

TEST(ExtensionSection, StructureIsChecked) {
  ExpectError("<ros2 node=\"a\" node=\"b\"/>", "t.xml:5: error: duplicate attribute 'node' on <ros2> (first at line 5)");
  ExpectError("<ros2 node=\"a &bogus; b\"/>", "t.xml:5: error: invalid entity reference '&bogus;' in the value of node");
  ExpectError("<ros2 node=\"a\">text</ros2>", "t.xml:5: error: unexpected text 'text' inside <ros2>");
  ExpectError("<ros2><x>\n<y a=\"1\" a=\"2\"/></x></ros2>", "t.xml:6: error: duplicate attribute 'a' on <y>");
  // Only the extension sections the core knows are accepted: a typo is still an error.
  ExpectError("<ros3 node=\"a\"/>", "t.xml:5: error: unknown element <ros3> in <ccomm> (did you mean 'ros2'?)");
}

TEST(ExtensionSection, ErrorFormat) {
  EXPECT_EQ(ConfigError("f.xml", 3, "bad"), "f.xml:3: error: bad");
  EXPECT_EQ(ConfigError("f.xml", 0, "bad"), "f.xml: error: bad");
  std::vector<std::string> items;
  EXPECT_TRUE(SplitConfigList("a, b c", &items));
  EXPECT_EQ(items, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_FALSE(SplitConfigList("a,,b", &items));
  EXPECT_FALSE(SplitConfigList("a,", &items));
}

}  // namespace
}  // namespace ccomm
