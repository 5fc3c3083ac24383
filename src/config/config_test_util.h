// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the config unit tests (config_test, config_hash_test, config_errors_test).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "config/config.h"
#include "testing/config_document.h"

#ifndef CCOMM_SOURCE_DIR
#error "CCOMM_SOURCE_DIR must point at the source tree (set by src/config/CMakeLists.txt)"
#endif

namespace ccomm {

// $CCOMM_SOURCE_DIR first: on a target (ptest) the test data is installed elsewhere.
inline const std::string kSourceDir = getenv("CCOMM_SOURCE_DIR") ? getenv("CCOMM_SOURCE_DIR") : CCOMM_SOURCE_DIR;

// Parses `xml`, expecting success; returns the model.
inline SystemConfig MustParse(const std::string& xml) {
  SystemConfig cfg;
  std::string err;
  EXPECT_TRUE(ParseConfig(xml, "test.xml", &cfg, &err)) << err << "\n--- input:\n" << xml;
  return cfg;
}

// Parses `xml`, expecting failure; returns the error text.
inline std::string MustFail(const std::string& xml) {
  SystemConfig cfg;
  std::string err;
  EXPECT_FALSE(ParseConfig(xml, "test.xml", &cfg, &err)) << "accepted:\n" << xml;
  return err;
}

// Two raw nodes a, b (lines 2-3) and the given extra lines inside <ccomm> from line 4
// (testing/config_document.h: the tests' one two-node document).
inline std::string TwoNodes(const std::string& body) { return testing::TwoNodeXml(body); }

// The *.xml files directly in `dir`, sorted.
inline std::vector<std::string> XmlFilesIn(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".xml") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace ccomm
