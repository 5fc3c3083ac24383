// SPDX-License-Identifier: Apache-2.0
// libFuzzer target of the --at / CONFIG.staged.at text (switch_at::ParseInstant), held to
// a plain reference: digits, an optional '.' and up to 9 more digits, nothing else.
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <string>

#include "daemon/service/switch_request.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const uint64_t got = ccomm::switch_at::ParseInstant(text.c_str());
  const size_t end = text.find('\0');
  const std::string s = text.substr(0, end);
  const size_t dot = s.find('.');
  const std::string whole = s.substr(0, dot), frac = dot == std::string::npos ? "" : s.substr(dot + 1);
  bool valid = !whole.empty() && whole.size() <= 10 && frac.size() <= 9 &&
               whole.find_first_not_of("0123456789") == std::string::npos &&
               frac.find_first_not_of("0123456789") == std::string::npos;
  uint64_t want = 0;
  if (valid) {
    std::string ns = frac;
    ns.resize(9, '0');
    want = strtoull(whole.c_str(), nullptr, 10) * 1000000000ull + strtoull(ns.c_str(), nullptr, 10);
  }
  if (got != want) abort();
  return 0;
}
