// SPDX-License-Identifier: Apache-2.0
// The shared parts of a switch at an instant (switch_request.h): the --at text, the staged
// file's identity (deploy aborts by removing or replacing it) and CONFIG.staged.at.
#include <gtest/gtest.h>
#include <stdio.h>
#include <unistd.h>

#include <string>

#include "common/platform.h"
#include "daemon/service/switch_request.h"

namespace ccomm {
namespace switch_at {
namespace {

TEST(ParseInstant, SecondsWithUpToNineDecimals) {
  EXPECT_EQ(ParseInstant("1764748800"), 1764748800ull * 1000000000);
  EXPECT_EQ(ParseInstant("1764748800.25"), 1764748800ull * 1000000000 + 250000000);
  EXPECT_EQ(ParseInstant("1764748800.000000001"), 1764748800ull * 1000000000 + 1);
  EXPECT_EQ(ParseInstant("1764748800."), 1764748800ull * 1000000000);
  EXPECT_EQ(ParseInstant("9999999999.999999999"), 9999999999999999999ull);  // the largest: no overflow
}

TEST(ParseInstant, AnythingElseIsZero) {
  for (const char* bad : {"", "soon", "-1", "+5", ".5", "1764748800.0000000001", "1764748800,5", "17647 48800",
                          "1764748800s", "99999999999", "0x10"})
    EXPECT_EQ(ParseInstant(bad), 0u) << bad;
  EXPECT_EQ(ParseInstant(nullptr), 0u);
}

TEST(StagedFile, ReplacedOrRemovedIsNotTheSame) {
  char dir[] = "/tmp/ccomm-switch-XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string config = std::string(dir) + "/signals.xml";
  const std::string staged = StagedPath(config);
  EXPECT_EQ(staged, config + ".staged");
  EXPECT_EQ(InstantPath(config), config + ".staged.at");
  FILE* f = fopen(staged.c_str(), "w");
  ASSERT_NE(f, nullptr);
  fputs("<ccomm/>\n", f);
  fclose(f);
  const platform::FileIdentity checked = platform::IdentifyFile(staged.c_str());
  ASSERT_TRUE(checked.valid);
  EXPECT_TRUE(platform::SameFile(checked, platform::IdentifyFile(staged.c_str())));
  // Another file moved in its place (what a second deploy does): not the one checked.
  const std::string other = staged + ".tmp";
  f = fopen(other.c_str(), "w");
  ASSERT_NE(f, nullptr);
  fputs("<ccomm/>\n", f);
  fclose(f);
  ASSERT_EQ(rename(other.c_str(), staged.c_str()), 0);
  EXPECT_FALSE(platform::SameFile(checked, platform::IdentifyFile(staged.c_str())));
  unlink(staged.c_str());
  EXPECT_FALSE(platform::IdentifyFile(staged.c_str()).valid);
  EXPECT_FALSE(platform::SameFile(checked, platform::IdentifyFile(staged.c_str())));

  std::string why;
  EXPECT_EQ(ReadInstant(config, &why), 0u);
  EXPECT_NE(why, "");
  f = fopen(InstantPath(config).c_str(), "w");
  ASSERT_NE(f, nullptr);
  fputs("1764748800.5\n", f);
  fclose(f);
  EXPECT_EQ(ReadInstant(config, &why), 1764748800ull * 1000000000 + 500000000) << why;
  f = fopen(InstantPath(config).c_str(), "w");
  ASSERT_NE(f, nullptr);
  fputs("tomorrow\n", f);
  fclose(f);
  why.clear();
  EXPECT_EQ(ReadInstant(config, &why), 0u);
  EXPECT_NE(why, "");
  unlink(InstantPath(config).c_str());
  rmdir(dir);
}

}  // namespace
}  // namespace switch_at
}  // namespace ccomm
