// SPDX-License-Identifier: Apache-2.0
#include "cli/values.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmath>
#include <vector>


namespace ccomm {
namespace cli {

const char* TypeName(int type) {
  const char* name = ccomm_type_name(type);
  return name ? name : "?";
}

static size_t ElemSize(int type) { return ccomm_type_size(type); }

static std::string FormatOne(int type, const uint8_t* p) {
  char buf[64];
  switch (type) {
    case CCOMM_BOOL: return *p ? "true" : "false";
    case CCOMM_INT32: { int32_t v; memcpy(&v, p, 4); snprintf(buf, sizeof buf, "%" PRId32, v); break; }
    case CCOMM_UINT32: { uint32_t v; memcpy(&v, p, 4); snprintf(buf, sizeof buf, "%" PRIu32, v); break; }
    case CCOMM_INT64: { int64_t v; memcpy(&v, p, 8); snprintf(buf, sizeof buf, "%" PRId64, v); break; }
    case CCOMM_FLOAT: {
      float v;
      memcpy(&v, p, 4);
      for (int prec = 6; prec <= 9; ++prec) {  // shortest text that reads back exactly
        snprintf(buf, sizeof buf, "%.*g", prec, static_cast<double>(v));
        if (strtof(buf, nullptr) == v) break;
      }
      break;
    }
    case CCOMM_DOUBLE: {
      double v;
      memcpy(&v, p, 8);
      for (int prec = 15; prec <= 17; ++prec) {
        snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (strtod(buf, nullptr) == v) break;
      }
      break;
    }
    default: return "?";
  }
  return buf;
}

std::string FormatValue(const ccomm_signal_desc& d, const void* value) {
  const uint8_t* p = static_cast<const uint8_t*>(value);
  size_t es = ElemSize(d.type);
  if (d.count == 1) return FormatOne(d.type, p);
  std::string s = "[";
  for (uint32_t i = 0; i < d.count; ++i) {
    if (i) s += ", ";
    s += FormatOne(d.type, p + i * es);
  }
  return s + "]";
}

// The configuration's parser (safe_value) reads the same words the same way: one rule.
static bool ParseOne(int type, const std::string& w, uint8_t* out, std::string* error) {
  const int r = ccomm_parse_element(type, w.c_str(), out);
  if (r == 0) return true;
  if (!ccomm_type_name(type)) *error = "unknown type";
  else if (r == CCOMM_E_TYPE) *error = "'" + w + "' is out of range for " + TypeName(type);
  else if (type == CCOMM_BOOL) *error = "'" + w + "' is not a bool (0, 1, true, false)";
  else *error = "'" + w + "' is not a valid " + TypeName(type);
  return false;
}

bool LooksLikeNumber(const char* word) {
  uint8_t v[8];
  return ccomm_parse_element(CCOMM_DOUBLE, word, v) != CCOMM_E_INVAL ||
         ccomm_parse_element(CCOMM_INT64, word, v) != CCOMM_E_INVAL;  // -0x10
}

bool ParseValue(const ccomm_signal_desc& d, int n, char** words, void* out, std::string* error) {
  std::vector<std::string> parts;
  for (int i = 0; i < n; ++i) {
    std::string w = words[i];
    size_t start = 0;
    for (;;) {
      size_t comma = w.find(',', start);
      std::string p = w.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      while (!p.empty() && (p[0] == '[' || p[0] == ' ')) p.erase(0, 1);
      while (!p.empty() && (p.back() == ']' || p.back() == ' ')) p.pop_back();
      if (!p.empty()) parts.push_back(p);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  if (parts.size() != 1 && parts.size() != d.count) {
    char buf[96];
    if (d.count == 1) snprintf(buf, sizeof buf, "expected 1 value, got %zu", parts.size());
    else snprintf(buf, sizeof buf, "expected 1 or %u values, got %zu", d.count, parts.size());
    *error = buf;
    return false;
  }
  uint8_t* p = static_cast<uint8_t*>(out);
  size_t es = ElemSize(d.type);
  for (uint32_t i = 0; i < d.count; ++i)
    if (!ParseOne(d.type, parts.size() == 1 ? parts[0] : parts[i], p + i * es, error)) return false;
  return true;
}

bool ParseOptionNumber(const char* word, bool integer, bool allow_zero, double* out) {
  char* end = nullptr;
  errno = 0;
  double v = strtod(word, &end);
  if (end == word || *end || errno == ERANGE || !std::isfinite(v)) return false;
  if (v < 0 || (v == 0 && !allow_zero) || (integer && (v != std::floor(v) || v > 9e15))) return false;
  *out = v;
  return true;
}

uint64_t WatchPeriodNs(double seconds) {
  const uint64_t whole = static_cast<uint64_t>(seconds);
  return whole * 1000000000u + static_cast<uint64_t>((seconds - static_cast<double>(whole)) * 1e9);
}

}  // namespace cli
}  // namespace ccomm
