// SPDX-License-Identifier: Apache-2.0
// Numbers and values as text, read one way everywhere (signals.xml and ccomm pub).
#pragma once

#include <stdint.h>

#include <string_view>

#include "common/value_type.h"

namespace ccomm {
namespace value_text {

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
/// "true"/"1" or "false"/"0"; false for anything else.
bool ParseBool(std::string_view s, bool* out);

}  // namespace value_text
}  // namespace ccomm
