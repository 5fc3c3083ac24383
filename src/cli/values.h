// SPDX-License-Identifier: Apache-2.0
// Text <-> value conversion for the CLI (host byte order, as in shared memory).
#pragma once

#include <cstdint>
#include <string>

#include "ccomm/ccomm.h"

namespace ccomm {
namespace cli {

const char* TypeName(int type);
/// "1.5" for scalars, "[1, 2, 3]" for arrays.
std::string FormatValue(const ccomm_signal_desc& d, const void* value);
/// Parses n words (one for all elements, or one per element; commas also separate).
/// False with a message on any malformed or out-of-range word.
/// Words are read as signals.xml reads a safe_value (config_detail::ParseValueElement).
bool ParseValue(const ccomm_signal_desc& d, int n, char** words, void* out, std::string* error);
/// True if `word` is a number ("-1.5", "-inf", "-nan"): a value, not an option.
bool LooksLikeNumber(const char* word);
/// An option's number: the whole word a finite decimal > 0 (>= 0 with allow_zero), and
/// integral when `integer`; false for "abc", "1x", "-1", "1.5" (integer), "inf".
bool ParseOptionNumber(const char* word, bool integer, bool allow_zero, double* out);
/// A --watch period of `seconds` (> 0) in ns: the whole seconds and the fraction's ns.
uint64_t WatchPeriodNs(double seconds);

}  // namespace cli
}  // namespace ccomm
