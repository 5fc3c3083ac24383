// SPDX-License-Identifier: Apache-2.0
// platform::GlobMatch: the same answers from every platform unit (glibc's fnmatch on
// POSIX, the Windows unit's own matcher); part of platform_test on both.
#include <gtest/gtest.h>

#include "common/platform.h"

namespace {

struct Case {
  const char* pattern;
  const char* name;
  bool match;
};

TEST(GlobMatch, AsFnmatchWithNoFlags) {
  const Case cases[] = {
      {"*", "", true},           {"*", "anything", true},       {"joint*", "joint_3", true},
      {"joint*", "xjoint", false}, {"*_cmd", "arm_cmd", true},    {"*_cmd", "arm_cmd2", false},
      {"a?c", "abc", true},      {"a?c", "ac", false},          {"a*b*c", "axxbyyc", true},
      {"a*b*c", "axxbyy", false}, {"[ab]x", "bx", true},          {"[ab]x", "cx", false},
      {"[!ab]x", "cx", true},    {"[!ab]x", "ax", false},       {"j[0-9]", "j7", true},
      {"j[0-9]", "ja", false},   {"[]]", "]", true},            {"a\\*", "a*", true},
      {"a\\*", "ab", false},     {"[", "[", true},              {"exact", "exact", true},
      {"exact", "exactly", false}, {"**x", "abx", true},
  };
  for (const Case& c : cases)
    EXPECT_EQ(ccomm::platform::GlobMatch(c.pattern, c.name), c.match) << c.pattern << " vs " << c.name;
}

}  // namespace
