// SPDX-License-Identifier: Apache-2.0
// Lexical pieces of the configuration parser: numbers, lists, addresses, entities,
// and the quoting/suggesting of words in error messages. No XML, no diagnostics.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/value_type.h"

namespace ccomm {
namespace config_detail {

/// 'word' with control characters escaped, for messages.
std::string Quote(std::string_view s);
std::string Join(const std::vector<std::string>& items, const char* sep);
/// " (did you mean 'x'?)" when exactly one candidate is close to `word`, else "".
std::string Suggest(std::string_view word, const std::vector<std::string>& candidates);

enum class NumResult { kOk, kSyntax, kRange };
/// Unsigned integer: decimal digits, or (allow_hex) 0x followed by hex digits.
NumResult ParseU64(std::string_view s, uint64_t* out, bool allow_hex = true);
/// Signed integer: optional '-', then as ParseU64.
NumResult ParseI64(std::string_view s, int64_t* out, bool allow_hex = true);
/// One element of a value of type `type` as the configuration (safe_value) and `ccomm
/// pub` both read it: bool true/false/1/0; integers decimal or 0x hex ('-' for signed, no
/// '+'); float and double in C syntax, inf and nan included (std::from_chars: no '+', no
/// locale). kRange when it does not fit the type (a float overflows or underflows to
/// 0/inf: never silently). Writes ValueTypeSize(type) bytes, host order, to `out`.
NumResult ParseValueElement(ValueType type, std::string_view s, void* out);
/// Non-negative decimal with up to `scale` fractional digits, times 10^scale.
NumResult ParseFixed(std::string_view s, int scale, uint64_t* out);
/// Items separated by blanks and/or single commas; false on an empty item.
bool SplitList(std::string_view v, std::vector<std::string_view>* items);
bool ParseBool(std::string_view s, bool* out);
/// Strict dotted quad (no leading zeros).
bool ParseIpv4(std::string_view s, uint8_t out[4]);
/// "02:00:5e:10:00:01".
bool ParseMac(std::string_view s, uint8_t out[6]);
/// Decodes XML entity references; on a malformed one returns false and sets *bad.
bool DecodeEntities(std::string_view raw, std::string* out, std::string* bad);

}  // namespace config_detail
}  // namespace ccomm
