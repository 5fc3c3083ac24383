// SPDX-License-Identifier: Apache-2.0
// The value types of ccomm signals: the one definition of their codes and sizes.
//
// The codes are the wire's type codes (docs/protocol.md), the store directory's `type`
// byte and the public API's ccomm_type values; config, wire, store, daemon and client all
// take them from here (the public header's enum is checked against them in client.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

namespace ccomm {

enum class ValueType : uint8_t {
  kBool = 1,
  kInt32 = 2,
  kUint32 = 3,
  kInt64 = 4,
  kFloat = 5,
  kDouble = 6,
};

constexpr ValueType kAllValueTypes[] = {ValueType::kBool,  ValueType::kInt32, ValueType::kUint32,
                                        ValueType::kInt64, ValueType::kFloat, ValueType::kDouble};

/// Bytes of one element of a type code (bool = 1 byte); 0 for an unknown code, so a code
/// read from a frame or from shared memory can be checked with it.
constexpr size_t ValueTypeSize(uint8_t code) {
  switch (code) {
    case 1: return 1;                   // bool
    case 2: case 3: case 5: return 4;   // int32, uint32, float
    case 4: case 6: return 8;           // int64, double
    default: return 0;
  }
}
constexpr size_t ValueTypeSize(ValueType t) { return ValueTypeSize(static_cast<uint8_t>(t)); }

/// "bool", "int32", ...; nullptr for an unknown code.
constexpr const char* ValueTypeName(ValueType t) {
  switch (t) {
    case ValueType::kBool: return "bool";
    case ValueType::kInt32: return "int32";
    case ValueType::kUint32: return "uint32";
    case ValueType::kInt64: return "int64";
    case ValueType::kFloat: return "float";
    case ValueType::kDouble: return "double";
  }
  return nullptr;
}

}  // namespace ccomm
