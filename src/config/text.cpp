// SPDX-License-Identifier: Apache-2.0
#include "config/text.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <limits>
#include <utility>

namespace ccomm {
namespace config_detail {

std::string Quote(std::string_view s) {
  std::string r = "'";
  for (char c : s) {
    unsigned char u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      r += buf;
    } else {
      r += c;
    }
  }
  r += "'";
  return r;
}

std::string Join(const std::vector<std::string>& items, const char* sep) {
  std::string r;
  for (size_t i = 0; i < items.size(); ++i) {
    if (i) r += sep;
    r += items[i];
  }
  return r;
}

static size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

// " (did you mean 'x'?)" when exactly one candidate is close to `word`, else "".
std::string Suggest(std::string_view word, const std::vector<std::string>& candidates) {
  const std::string* best = nullptr;
  size_t best_d = std::numeric_limits<size_t>::max();
  bool tie = false;
  for (const std::string& c : candidates) {
    size_t d = EditDistance(word, c);
    if (d < best_d) {
      best_d = d;
      best = &c;
      tie = false;
    } else if (d == best_d) {
      tie = true;
    }
  }
  size_t limit = std::max<size_t>(1, std::min<size_t>(3, word.size() / 3));
  if (best == nullptr || tie || best_d == 0 || best_d > limit) return "";
  return " (did you mean " + Quote(*best) + "?)";
}

// -------------------------------------------------------------- value parsing


// Unsigned integer: decimal digits, or (allow_hex) 0x followed by hex digits. No sign,
// no spaces.

// Signed integer: optional '-', then as ParseU64. Out of int64 range is kRange.



// Non-negative decimal with up to `scale` fractional digits, returned multiplied by
// 10^scale ("0.1" with scale 3 -> 100). Locale independent, exact.
NumResult ParseFixed(std::string_view s, int scale, uint64_t* out) {
  size_t dot = s.find('.');
  std::string_view ip = s.substr(0, dot);
  std::string_view fp = dot == std::string_view::npos ? std::string_view() : s.substr(dot + 1);
  if (ip.empty() || (dot != std::string_view::npos && fp.empty())) return NumResult::kSyntax;
  auto digits = [](std::string_view d) {
    return std::all_of(d.begin(), d.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (!digits(ip) || !digits(fp)) return NumResult::kSyntax;
  // Trailing zeros beyond the resolution are harmless ("0.1000"); other digits are not.
  while (fp.size() > static_cast<size_t>(scale) && fp.back() == '0') fp.remove_suffix(1);
  if (fp.size() > static_cast<size_t>(scale)) return NumResult::kSyntax;
  uint64_t v = 0;
  for (char c : ip) {
    if (v > 1000000000000ull) return NumResult::kRange;  // far beyond any sane setting
    v = v * 10 + static_cast<uint64_t>(c - '0');
  }
  for (int i = 0; i < scale; ++i) {
    v *= 10;
    if (static_cast<size_t>(i) < fp.size()) v += static_cast<uint64_t>(fp[i] - '0');
  }
  *out = v;
  return NumResult::kOk;
}

// Splits a list whose items are separated by blanks and/or single commas ("1 2", "1,2",
// "1, 2"). Returns false on an empty item (",1", "1,,2", "1,"). An all-blank string
// gives no items.
bool SplitList(std::string_view v, std::vector<std::string_view>* items) {
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  items->clear();
  size_t i = 0;
  bool after_comma = false;
  while (true) {
    while (i < v.size() && blank(v[i])) ++i;
    if (i == v.size()) return !after_comma;
    if (v[i] == ',') {
      if (items->empty() || after_comma) return false;
      after_comma = true;
      ++i;
      continue;
    }
    size_t b = i;
    while (i < v.size() && !blank(v[i]) && v[i] != ',') ++i;
    items->push_back(v.substr(b, i - b));
    after_comma = false;
  }
}


// Strict dotted quad: four decimal parts 0..255, no leading zeros (inet_aton would read
// "010" as octal 8, which is never what the author meant).
bool ParseIpv4(std::string_view s, uint8_t out[4]) {
  for (int i = 0; i < 4; ++i) {
    size_t n = 0;
    while (n < s.size() && s[n] >= '0' && s[n] <= '9') ++n;
    if (n == 0 || n > 3 || (n > 1 && s[0] == '0')) return false;
    unsigned v = 0;
    for (size_t k = 0; k < n; ++k) v = v * 10 + static_cast<unsigned>(s[k] - '0');
    if (v > 255) return false;
    out[i] = static_cast<uint8_t>(v);
    s.remove_prefix(n);
    if (i < 3) {
      if (s.empty() || s[0] != '.') return false;
      s.remove_prefix(1);
    }
  }
  return s.empty();
}

static int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// "02:00:5e:10:00:01": six pairs of hex digits separated by ':'.
bool ParseMac(std::string_view s, uint8_t out[6]) {
  if (s.size() != 17) return false;
  for (int i = 0; i < 6; ++i) {
    int hi = HexDigit(s[i * 3]), lo = HexDigit(s[i * 3 + 1]);
    if (hi < 0 || lo < 0) return false;
    if (i < 5 && s[i * 3 + 2] != ':') return false;
    out[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  return true;
}

static void AppendUtf8(uint32_t cp, std::string* out) {
  if (cp < 0x80) {
    *out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    *out += static_cast<char>(0xC0 | (cp >> 6));
    *out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    *out += static_cast<char>(0xE0 | (cp >> 12));
    *out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    *out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    *out += static_cast<char>(0xF0 | (cp >> 18));
    *out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    *out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    *out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// Attribute values come raw (parse_non_destructive): decode the XML entity references
// here. On a malformed one returns false and sets *bad to it.
bool DecodeEntities(std::string_view raw, std::string* out, std::string* bad) {
  out->clear();
  for (size_t i = 0; i < raw.size(); ++i) {
    char c = raw[i];
    if (c == '<') {
      *bad = "<";
      return false;
    }
    if (c != '&') {
      *out += c;
      continue;
    }
    size_t semi = raw.find(';', i);
    if (semi == std::string_view::npos || semi - i > 10) {
      *bad = std::string(raw.substr(i, std::min<size_t>(raw.size() - i, 10)));
      return false;
    }
    std::string_view ent = raw.substr(i + 1, semi - i - 1);
    if (ent == "lt") *out += '<';
    else if (ent == "gt") *out += '>';
    else if (ent == "amp") *out += '&';
    else if (ent == "quot") *out += '"';
    else if (ent == "apos") *out += '\'';
    else if (ent.size() >= 2 && ent[0] == '#') {
      uint64_t cp = 0;
      std::string_view num = ent.substr(1);
      int base = 10;
      if (num[0] == 'x') {
        base = 16;
        num.remove_prefix(1);
      }
      auto r = std::from_chars(num.data(), num.data() + num.size(), cp, base);
      if (num.empty() || r.ec != std::errc() || r.ptr != num.data() + num.size() || cp == 0 ||
          cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) {
        *bad = "&" + std::string(ent) + ";";
        return false;
      }
      AppendUtf8(static_cast<uint32_t>(cp), out);
    } else {
      *bad = "&" + std::string(ent) + ";";
      return false;
    }
    i = semi;
  }
  return true;
}


}  // namespace config_detail
}  // namespace ccomm
