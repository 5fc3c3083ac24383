// SPDX-License-Identifier: Apache-2.0
// Lexical pieces of the configuration parser: numbers, lists, addresses, entities,
// and the quoting/suggesting of words in error messages. No XML, no diagnostics.
#pragma once

#include "common/value_text.h"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/value_type.h"

namespace ccomm {
namespace config_detail {

// The value readers live in common/ (libccomm reads `ccomm pub` words with them too).
using value_text::NumResult;
using value_text::ParseBool;
using value_text::ParseI64;
using value_text::ParseU64;
using value_text::ParseValueElement;


/// 'word' with control characters escaped, for messages.
std::string Quote(std::string_view s);
std::string Join(const std::vector<std::string>& items, const char* sep);
/// " (did you mean 'x'?)" when exactly one candidate is close to `word`, else "".
std::string Suggest(std::string_view word, const std::vector<std::string>& candidates);

/// Non-negative decimal with up to `scale` fractional digits, times 10^scale.
NumResult ParseFixed(std::string_view s, int scale, uint64_t* out);
/// Items separated by blanks and/or single commas; false on an empty item.
bool SplitList(std::string_view v, std::vector<std::string_view>* items);
/// Strict dotted quad (no leading zeros).
bool ParseIpv4(std::string_view s, uint8_t out[4]);
/// "02:00:5e:10:00:01".
bool ParseMac(std::string_view s, uint8_t out[6]);
/// Decodes XML entity references; on a malformed one returns false and sets *bad.
bool DecodeEntities(std::string_view raw, std::string* out, std::string* bad);

}  // namespace config_detail
}  // namespace ccomm
