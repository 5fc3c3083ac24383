// SPDX-License-Identifier: Apache-2.0
// The applications' (ccomm, ccomm-latency) JSON output: one way to put a name or a label
// into a JSON string.
#pragma once

#include <cstdio>
#include <string>

namespace ccomm {
namespace app {

/// `text` as a JSON string's contents: quotes and backslashes escaped, control characters
/// as \u00XX (a label a user typed may hold any of them).
inline std::string JsonText(const char* text) {
  std::string out;
  for (const char* p = text; p != nullptr && *p != '\0'; ++p) {
    const unsigned char c = static_cast<unsigned char>(*p);
    if (c < 0x20) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\u%04x", c);
      out += hex;
      continue;
    }
    if (c == '"' || c == '\\') out += '\\';
    out += static_cast<char>(c);
  }
  return out;
}

}  // namespace app
}  // namespace ccomm
