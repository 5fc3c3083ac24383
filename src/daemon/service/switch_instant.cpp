// SPDX-License-Identifier: Apache-2.0
// The parts of a switch at an instant (switch_request.h) that every platform shares: the
// staged files' names and the instant's text (posix/ and windows/switch_request.cpp: the rest).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/platform.h"
#include "daemon/service/switch_request.h"

namespace ccomm {
namespace switch_at {

std::string StagedPath(const std::string& config) { return config + ".staged"; }
std::string InstantPath(const std::string& config) { return config + ".staged.at"; }

uint64_t ParseInstant(const char* text) {
  if (!text || !*text) return 0;
  uint64_t s = 0, frac = 0;
  int digits = 0, frac_digits = 0;
  const char* p = text;
  for (; *p >= '0' && *p <= '9'; ++p) {
    if (++digits > 10) return 0;  // past the year 2286: not a time (and 11 digits of ns overflow)
    s = s * 10 + static_cast<uint64_t>(*p - '0');
  }
  if (digits == 0) return 0;
  if (*p == '.') {
    for (++p; *p >= '0' && *p <= '9'; ++p) {
      if (++frac_digits > 9) return 0;
      frac = frac * 10 + static_cast<uint64_t>(*p - '0');
    }
  }
  if (*p) return 0;
  for (int i = frac_digits; i < 9; ++i) frac *= 10;
  return s * 1000000000ull + frac;
}

uint64_t ReadInstant(const std::string& config, std::string* why) {
  const std::string path = InstantPath(config);
  std::string text;
  uint64_t size = 0;
  const int r = platform::ReadRegularFile(path.c_str(), 64, &text, &size);
  if (r != 0) {
    *why = path + ": cannot read the switch instant: " + strerror(-r);
    return 0;
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  const uint64_t at = ParseInstant(text.c_str());
  if (!at) *why = path + ": '" + text + "' is no instant (seconds since the epoch, up to 9 decimals)";
  return at;
}

}  // namespace switch_at
}  // namespace ccomm
