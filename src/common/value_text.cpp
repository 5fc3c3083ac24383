// SPDX-License-Identifier: Apache-2.0
// Numbers and values as text: the one reader of signals.xml's values (safe_value, via
// config/text.h) and of `ccomm pub` (via ccomm_parse_element in libccomm).
#include "common/value_text.h"

#include <charconv>
#include <cstring>
#include <limits>

namespace ccomm {
namespace value_text {

NumResult ParseU64(std::string_view s, uint64_t* out, bool allow_hex) {
  int base = 10;
  if (allow_hex && s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  }
  if (s.empty()) return NumResult::kSyntax;
  uint64_t v = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (r.ptr != s.data() + s.size()) {
    // from_chars stops at the first bad character; an overflowing number is still
    // all digits, so tell the two apart.
    if (r.ec == std::errc::result_out_of_range) return NumResult::kRange;
    return NumResult::kSyntax;
  }
  if (r.ec == std::errc::result_out_of_range) return NumResult::kRange;
  if (r.ec != std::errc()) return NumResult::kSyntax;
  *out = v;
  return NumResult::kOk;
}

NumResult ParseI64(std::string_view s, int64_t* out, bool allow_hex) {
  bool neg = !s.empty() && s[0] == '-';
  if (neg) s.remove_prefix(1);
  uint64_t mag = 0;
  NumResult r = ParseU64(s, &mag, allow_hex);
  if (r != NumResult::kOk) return r;
  const uint64_t limit = neg ? uint64_t{1} << 63 : (uint64_t{1} << 63) - 1;
  if (mag > limit) return NumResult::kRange;
  *out = neg ? static_cast<int64_t>(0 - mag) : static_cast<int64_t>(mag);
  return NumResult::kOk;
}

bool ParseBool(std::string_view s, bool* out) {
  if (s == "true" || s == "1") {
    *out = true;
    return true;
  }
  if (s == "false" || s == "0") {
    *out = false;
    return true;
  }
  return false;
}

namespace {
template <typename T>
NumResult ParseReal(std::string_view s, void* out) {
  T v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ptr != s.data() + s.size()) return NumResult::kSyntax;
  if (r.ec == std::errc::result_out_of_range) return NumResult::kRange;
  if (r.ec != std::errc()) return NumResult::kSyntax;
  std::memcpy(out, &v, sizeof v);
  return NumResult::kOk;
}
}  // namespace

NumResult ParseValueElement(ValueType type, std::string_view s, void* out) {
  switch (type) {
    case ValueType::kBool: {
      bool b = false;
      if (!ParseBool(s, &b)) return NumResult::kSyntax;
      const uint8_t byte = b ? 1 : 0;
      std::memcpy(out, &byte, 1);
      return NumResult::kOk;
    }
    case ValueType::kInt32:
    case ValueType::kInt64: {
      int64_t x = 0;
      const NumResult r = ParseI64(s, &x);
      if (r != NumResult::kOk) return r;
      if (type == ValueType::kInt64) {
        std::memcpy(out, &x, 8);
        return NumResult::kOk;
      }
      if (x < std::numeric_limits<int32_t>::min() || x > std::numeric_limits<int32_t>::max()) return NumResult::kRange;
      const int32_t y = static_cast<int32_t>(x);
      std::memcpy(out, &y, 4);
      return NumResult::kOk;
    }
    case ValueType::kUint32: {
      if (s.size() > 1 && s[0] == '-') return NumResult::kRange;
      uint64_t x = 0;
      const NumResult r = ParseU64(s, &x);
      if (r != NumResult::kOk) return r;
      if (x > std::numeric_limits<uint32_t>::max()) return NumResult::kRange;
      const uint32_t y = static_cast<uint32_t>(x);
      std::memcpy(out, &y, 4);
      return NumResult::kOk;
    }
    case ValueType::kFloat: return ParseReal<float>(s, out);
    case ValueType::kDouble: return ParseReal<double>(s, out);
  }
  return NumResult::kSyntax;
}

}  // namespace value_text
}  // namespace ccomm
