// SPDX-License-Identifier: Apache-2.0
// WriteFileAtomically and IdentifyFile (common/platform.h), the same test on every platform.
#include <gtest/gtest.h>

#include <errno.h>
#include <stdio.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "common/platform.h"

namespace ccomm {
namespace {

std::string Scratch(const char* name) {
  const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  const auto dir = std::filesystem::temp_directory_path() / ("ccomm-files-test-" + std::to_string(stamp));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

std::string Contents(const std::string& path) {
  std::string text;
  uint64_t size = 0;
  return platform::ReadRegularFile(path.c_str(), 1 << 20, &text, &size) == 0 ? text : "(unreadable)";
}

TEST(WriteFileAtomically, ReplacesTheFileWholeAndLeavesNoTemporaryFile) {
  const std::string path = Scratch("signals.xml");
  ASSERT_EQ(platform::WriteFileAtomically(path.c_str(), "first"), 0);
  EXPECT_EQ(Contents(path), "first");
  ASSERT_EQ(platform::WriteFileAtomically(path.c_str(), std::string(100000, 'x')), 0);
  EXPECT_EQ(Contents(path), std::string(100000, 'x'));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

TEST(WriteFileAtomically, SaysWhyWhenTheDirectoryIsMissing) {
  const std::string path = Scratch("x") + "-no-such-dir/file";
  EXPECT_EQ(platform::WriteFileAtomically(path.c_str(), "text"), -ENOENT);
}

TEST(IdentifyFile, TellsAFileFromTheOneThatReplacedIt) {
  const std::string path = Scratch("staged");
  EXPECT_FALSE(platform::IdentifyFile(path.c_str()).valid);
  ASSERT_EQ(platform::WriteFileAtomically(path.c_str(), "one"), 0);
  const platform::FileIdentity first = platform::IdentifyFile(path.c_str());
  ASSERT_TRUE(first.valid);
  EXPECT_EQ(first.size, 3u);
  EXPECT_TRUE(platform::SameFile(first, platform::IdentifyFile(path.c_str())));
  // The same size and name, written again: a new file (rename), so not the same.
  ASSERT_EQ(platform::WriteFileAtomically(path.c_str(), "two"), 0);
  EXPECT_FALSE(platform::SameFile(first, platform::IdentifyFile(path.c_str())));
  std::filesystem::remove(path);
  EXPECT_FALSE(platform::SameFile(first, platform::IdentifyFile(path.c_str())));
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

}  // namespace
}  // namespace ccomm
