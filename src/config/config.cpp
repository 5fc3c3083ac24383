// SPDX-License-Identifier: Apache-2.0
// Parser and validator for signals.xml (format: docs/config.md, schema: docs/signals.xsd).
//
// RapidXML builds the DOM; everything else (line numbers, entity decoding, every semantic
// check) is done here so that every mistake in the file is reported with FILE:LINE, and
// all of them at once rather than one per run.

#define RAPIDXML_NO_EXCEPTIONS
#include <rapidxml/rapidxml.hpp>

#include "config/config.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string_view>
#include <utility>

// ---------------------------------------------------------------------------------------
// RapidXML error handling without exceptions.
//
// Core code is built with -fno-exceptions, so RapidXML calls this handler instead of
// throwing, and the handler must not return. We longjmp back to RunXmlParse(), which is
// safe because:
//  * C++ allows longjmp exactly when an equivalent throw/catch would run no non-trivial
//    destructors ([csetjmp.syn]). Every frame between RunXmlParse() and the handler is a
//    RapidXML parse function, whose automatic objects are all raw pointers and chars.
//  * RunXmlParse() modifies no local variable after setjmp(), so nothing is indeterminate
//    after the jump.
//  * Nodes already built live in the document's memory pool, which records every block
//    when it is allocated; ~xml_document() frees them as usual.
//  * The jump target is thread-local, so parses on different threads do not interfere.
//    A parse that is not running under RunXmlParse() (nobody else in ccomm uses RapidXML)
//    aborts instead of returning into RapidXML.
namespace {
struct XmlFailure {
  std::jmp_buf env;
  const char* what = nullptr;
  const char* where = nullptr;
};
thread_local XmlFailure* t_xml_failure = nullptr;
}  // namespace

namespace rapidxml {
void parse_error_handler(const char* what, void* where) {
  XmlFailure* f = t_xml_failure;
  if (f == nullptr) std::abort();
  f->what = what;
  f->where = static_cast<const char*>(where);
  std::longjmp(f->env, 1);
}
}  // namespace rapidxml

namespace ccomm {

bool ParseValueType(const std::string& name, ValueType* out) {
  for (ValueType t : kAllValueTypes) {
    if (name == ValueTypeName(t)) {
      *out = t;
      return true;
    }
  }
  return false;
}

int SystemConfig::FindNode(const std::string& name) const {
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].name == name) return static_cast<int>(i);
  return -1;
}

int SystemConfig::FindSignal(const std::string& name) const {
  for (size_t i = 0; i < signals.size(); ++i)
    if (signals[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

using Node = rapidxml::xml_node<char>;
using Attribute = rapidxml::xml_attribute<char>;

// Beyond this many messages the rest are usually consequences of the first ones.
constexpr size_t kMaxReportedErrors = 50;
// A real configuration is well under 1 MiB (4096 signals is about 600 KiB); refuse
// anything absurd rather than allocating for it.
constexpr size_t kMaxFileBytes = 16u << 20;

// Ranges of the numeric settings (documented in docs/config.md).
constexpr uint32_t kMinPeriodUs = 50;
constexpr uint32_t kMaxPeriodUs = 60u * 1000 * 1000;
constexpr uint32_t kMaxStaleAfterMs = 3600u * 1000;
constexpr uint32_t kMaxHeartbeatMs = 10000;
constexpr uint32_t kMaxPeerTimeoutMs = 60000;
constexpr uint32_t kMaxSpinUs = 100000;
constexpr int kMaxCpu = 1023;  // CPU_SETSIZE - 1
constexpr uint32_t kMinQueueDepth = 2;
constexpr uint32_t kMaxQueueDepth = 65536;
constexpr size_t kMaxInterfaceName = 15;  // IFNAMSIZ - 1

std::string_view NameOf(const Node* n) { return std::string_view(n->name(), n->name_size()); }
std::string_view NameOf(const Attribute* a) {
  return std::string_view(a->name(), a->name_size());
}

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

size_t EditDistance(std::string_view a, std::string_view b) {
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

// ------------------------------------------------------------------ diagnostics

class Diagnostics {
 public:
  Diagnostics(std::string path, const char* begin, size_t size)
      : path_(std::move(path)), begin_(begin), size_(size) {
    line_starts_.push_back(0);
    for (size_t i = 0; i < size; ++i)
      if (begin[i] == '\n') line_starts_.push_back(i + 1);
  }

  // 1-based line of a pointer into the text; 0 if it does not point into it.
  int LineOf(const char* p) const {
    if (p == nullptr || p < begin_ || p > begin_ + size_) return 0;
    size_t off = static_cast<size_t>(p - begin_);
    auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), off);
    return static_cast<int>(it - line_starts_.begin());
  }

  void Error(int line, std::string message) {
    entries_.push_back({line, std::move(message)});
    // Only the first kMaxReportedErrors by line are reported, but cross-reference errors
    // arrive after the walk and may belong before stored ones: trim now and then to the
    // lowest lines seen so far instead of dropping late arrivals.
    if (entries_.size() >= 20 * kMaxReportedErrors) Trim();
  }

  bool empty() const { return entries_.empty(); }

  // Messages in line order (cross-reference checks run after the walk), capped.
  std::string Render() {
    Trim();
    std::string out;
    size_t n = std::min(entries_.size(), kMaxReportedErrors);
    for (size_t i = 0; i < n; ++i) {
      if (i) out += '\n';
      out += Prefix(entries_[i].line) + entries_[i].message;
    }
    if (overflow_) {
      out += '\n';
      out += Prefix(0) + "too many errors; stopped after " + std::to_string(kMaxReportedErrors);
    }
    return out;
  }

 private:
  struct Entry {
    int line;
    std::string message;
  };
  // Sorts by line (stable: equal lines keep the order they were found in) and keeps the
  // first kMaxReportedErrors.
  void Trim() {
    std::stable_sort(entries_.begin(), entries_.end(),
                     [](const Entry& a, const Entry& b) { return a.line < b.line; });
    if (entries_.size() > kMaxReportedErrors) {
      entries_.resize(kMaxReportedErrors);
      overflow_ = true;
    }
  }
  std::string Prefix(int line) const {
    if (line <= 0) return path_ + ": error: ";
    return path_ + ":" + std::to_string(line) + ": error: ";
  }

  std::string path_;
  const char* begin_;
  size_t size_;
  std::vector<size_t> line_starts_;
  std::vector<Entry> entries_;
  bool overflow_ = false;
};

// -------------------------------------------------------------- value parsing

enum class NumResult { kOk, kSyntax, kRange };

// Unsigned integer: decimal digits, or (allow_hex) 0x followed by hex digits. No sign,
// no spaces.
NumResult ParseU64(std::string_view s, uint64_t* out, bool allow_hex = true) {
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

// Signed integer: optional '-', then as ParseU64. Out of int64 range is kRange.
NumResult ParseI64(std::string_view s, int64_t* out, bool allow_hex = true) {
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

int HexDigit(char c) {
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

void AppendUtf8(uint32_t cp, std::string* out) {
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

// ---------------------------------------------------------------- elements

struct AttrValue {
  std::string value;
  int line = 0;
};

// The attributes of one element, checked against the names it accepts.
class Element {
 public:
  Element(const Node* node, std::vector<const char*> allowed, Diagnostics* diag)
      : tag_(NameOf(node)), allowed_(std::move(allowed)), values_(allowed_.size()),
        present_(allowed_.size(), false), bad_(allowed_.size(), false) {
    line_ = diag->LineOf(node->name());
    for (const Attribute* a = node->first_attribute(); a; a = a->next_attribute()) {
      std::string_view name = NameOf(a);
      int line = diag->LineOf(a->name());
      size_t idx = Index(name);
      if (idx == allowed_.size()) {
        std::vector<std::string> names(allowed_.begin(), allowed_.end());
        std::string hint = Suggest(name, names);
        if (hint.empty()) hint = " (expected " + Join(names, ", ") + ")";
        diag->Error(line, "unknown attribute " + Quote(name) + " on <" + std::string(tag_) + ">" +
                              hint);
        continue;
      }
      if (present_[idx]) {
        diag->Error(line, "duplicate attribute " + Quote(name) + " on <" + std::string(tag_) +
                              "> (first at line " + std::to_string(values_[idx].line) + ")");
        continue;
      }
      std::string decoded, bad;
      if (!DecodeEntities(std::string_view(a->value(), a->value_size()), &decoded, &bad)) {
        if (bad == "<")
          diag->Error(line, "'<' in the value of " + std::string(name) + " (write &lt;)");
        else
          diag->Error(line, "invalid entity reference " + Quote(bad) + " in the value of " +
                                std::string(name));
        present_[idx] = true;  // reported; do not also report it as missing
        bad_[idx] = true;
        values_[idx].line = line;
        continue;
      }
      present_[idx] = true;
      values_[idx] = {std::move(decoded), line};
    }
  }

  int line() const { return line_; }
  const std::string_view& tag() const { return tag_; }

  // The attribute, or nullptr when absent (or already reported as undecodable).
  const AttrValue* Get(const char* name) const {
    size_t idx = Index(name);
    if (idx == allowed_.size() || !present_[idx] || bad_[idx]) return nullptr;
    return &values_[idx];
  }
  bool Has(const char* name) const {
    size_t idx = Index(name);
    return idx != allowed_.size() && present_[idx];
  }

 private:
  size_t Index(std::string_view name) const {
    for (size_t i = 0; i < allowed_.size(); ++i)
      if (name == allowed_[i]) return i;
    return allowed_.size();
  }

  std::string_view tag_;
  std::vector<const char*> allowed_;
  std::vector<AttrValue> values_;
  std::vector<bool> present_;
  std::vector<bool> bad_;  // present but undecodable (already reported)
  int line_ = 0;
};

// Reports text inside an element (everything in this format is an attribute).
void CheckNoText(const Node* parent, Diagnostics* diag) {
  for (const Node* c = parent->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_data && c->type() != rapidxml::node_cdata) continue;
    std::string_view v(c->value(), c->value_size());
    size_t first = v.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos) continue;
    std::string_view shown = v.substr(first, 20);
    size_t nl = shown.find_first_of("\r\n");
    if (nl != std::string_view::npos) shown = shown.substr(0, nl);
    diag->Error(diag->LineOf(c->value() + first),
                "unexpected text " + Quote(shown) + " inside <" + std::string(NameOf(parent)) +
                    "> (settings go in attributes)");
  }
}

class Parser {
 public:
  Parser(const std::string& path, const char* text, size_t size)
      : diag_(path, text, size) {}

  Diagnostics& diag() { return diag_; }

  void Run(const Node* doc, SystemConfig* cfg);

 private:
  struct SignalRefs {
    std::string producer;
    int producer_line = 0;
    std::vector<std::pair<std::string, int>> consumers;  // name, line
    bool ok = true;  // false: type/count unknown, skip size-dependent checks
  };

  void Root(const Node* root, SystemConfig* cfg);
  void Network(const Node* n, NetworkConfig* net);
  void NodeElement(const Node* n, bool only_node, NodeConfig* node);
  void Realtime(const Node* n, RealtimeConfig* rt);
  void SignalElement(const Node* n, SignalConfig* sig, SignalRefs* refs);
  void SafeValue(const AttrValue& a, SignalConfig* sig);
  void CrossCheck(SystemConfig* cfg);

  bool Name(const Element& e, const char* what, std::string* out);
  template <typename T>
  bool Unsigned(const Element& e, const char* attr, uint64_t lo, uint64_t hi, T* out,
                bool hex = false);
  bool Signed(const Element& e, const char* attr, int64_t lo, int64_t hi, int* out);
  /// Reports a number that did not parse or is outside `range`; true if it is fine.
  bool NumberOk(const AttrValue& a, const char* attr, NumResult r, bool in_range, const std::string& range);
  bool Bool(const Element& e, const char* attr, bool* out);
  void Err(int line, std::string msg) { diag_.Error(line, std::move(msg)); }

  Diagnostics diag_;
  std::vector<SignalRefs> refs_;
};

bool Parser::Name(const Element& e, const char* what, std::string* out) {
  const AttrValue* a = e.Get("name");
  if (a == nullptr) {
    if (!e.Has("name"))
      Err(e.line(), "<" + std::string(e.tag()) + "> without name=");
    return false;
  }
  const std::string& v = a->value;
  std::string w = what;
  if (v.empty()) {
    Err(a->line, "empty " + w + " name");
    return false;
  }
  for (char c : v) {
    bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
              c == '_' || c == '.' || c == '-';
    if (!ok) {
      std::string ch = (static_cast<unsigned char>(c) & 0x80) ? std::string("non-ASCII character")
                                                              : "invalid character " +
                                                                    Quote(std::string_view(&c, 1));
      Err(a->line, ch + " in " + w + " name " + Quote(v) + " (allowed: A-Z a-z 0-9 _ . -)");
      return false;
    }
  }
  if (v.size() > kMaxNameLength) {
    Err(a->line, w + " name " + Quote(v) + " is " + std::to_string(v.size()) +
                     " characters long (at most " + std::to_string(kMaxNameLength) + ")");
    return false;
  }
  if (v[0] == '.' || v[0] == '-') {
    Err(a->line, w + " name " + Quote(v) + " must not start with '.' or '-'");
    return false;
  }
  *out = v;
  return true;
}

bool Parser::NumberOk(const AttrValue& a, const char* attr, NumResult r, bool in_range,
                      const std::string& range) {
  if (r == NumResult::kSyntax) {
    Err(a.line, "invalid " + std::string(attr) + " " + Quote(a.value) + " (expected an integer " + range + ")");
    return false;
  }
  if (r == NumResult::kRange || !in_range) {
    Err(a.line, std::string(attr) + " " + a.value + " out of range (expected " + range + ")");
    return false;
  }
  return true;
}

template <typename T>
bool Parser::Unsigned(const Element& e, const char* attr, uint64_t lo, uint64_t hi, T* out,
                      bool hex) {
  const AttrValue* a = e.Get(attr);
  if (a == nullptr) return false;
  uint64_t v = 0;
  std::string range;
  if (hex) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "0x%04llX..0x%04llX", static_cast<unsigned long long>(lo),
                  static_cast<unsigned long long>(hi));
    range = buf;
  } else {
    range = std::to_string(lo) + ".." + std::to_string(hi);
  }
  // Hex only where it is the usual notation (EtherType); elsewhere "0x10" is a typo.
  NumResult r = ParseU64(a->value, &v, hex);
  if (!NumberOk(*a, attr, r, v >= lo && v <= hi, range)) return false;
  *out = static_cast<T>(v);
  return true;
}

bool Parser::Signed(const Element& e, const char* attr, int64_t lo, int64_t hi, int* out) {
  const AttrValue* a = e.Get(attr);
  if (a == nullptr) return false;
  int64_t v = 0;
  std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  NumResult r = ParseI64(a->value, &v, /*allow_hex=*/false);
  if (!NumberOk(*a, attr, r, v >= lo && v <= hi, range)) return false;
  *out = static_cast<int>(v);
  return true;
}

bool Parser::Bool(const Element& e, const char* attr, bool* out) {
  const AttrValue* a = e.Get(attr);
  if (a == nullptr) return false;
  if (!ParseBool(a->value, out)) {
    Err(a->line, "invalid " + std::string(attr) + " " + Quote(a->value) +
                     " (expected true, false, 1 or 0)");
    return false;
  }
  return true;
}

// XML forbids "--" inside a comment. RapidXML does not care, but xmllint, Python's
// ElementTree and editors reject such a file, and the same file must work for them too.
void CheckComments(const Node* parent, Diagnostics* diag) {
  for (const Node* c = parent->first_node(); c; c = c->next_sibling()) {
    if (c->type() == rapidxml::node_element) {
      CheckComments(c, diag);
      continue;
    }
    if (c->type() != rapidxml::node_comment) continue;
    std::string_view v(c->value(), c->value_size());
    size_t dd = v.find("--");
    if (dd == std::string_view::npos && !v.empty() && v.back() == '-') dd = v.size() - 1;
    if (dd != std::string_view::npos)
      diag->Error(diag->LineOf(c->value() + dd),
                  "'--' inside a comment (not allowed in XML; other XML tools reject the file)");
  }
}

void Parser::Run(const Node* doc, SystemConfig* cfg) {
  CheckComments(doc, &diag_);
  const Node* root = nullptr;
  for (const Node* c = doc->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_element) continue;
    if (root == nullptr) {
      root = c;
    } else {
      Err(diag_.LineOf(c->name()), "second root element <" + std::string(NameOf(c)) +
                                       "> (everything belongs inside <ccomm>)");
    }
  }
  if (root == nullptr) {
    Err(1, "no root element (expected <ccomm version=\"1\">)");
    return;
  }
  if (NameOf(root) != "ccomm") {
    Err(diag_.LineOf(root->name()), "root element is <" + std::string(NameOf(root)) +
                                        ">; expected <ccomm version=\"1\">");
    return;
  }
  Root(root, cfg);
  CrossCheck(cfg);
}

void Parser::Root(const Node* root, SystemConfig* cfg) {
  // xmlns:xsi / xsi:noNamespaceSchemaLocation let editors validate against signals.xsd.
  Element e(root, {"version", "xmlns:xsi", "xsi:noNamespaceSchemaLocation"}, &diag_);
  if (const AttrValue* v = e.Get("version")) {
    if (v->value != "1")
      Err(v->line, "unsupported format version " + Quote(v->value) +
                       " (this ccomm reads version 1)");
  } else if (!e.Has("version")) {
    Err(e.line(), "<ccomm> without version= (expected version=\"1\")");
  }
  CheckNoText(root, &diag_);

  int network_line = 0;
  int nodes_seen = 0, signals_seen = 0;
  int node_elements = 0;
  for (const Node* c = root->first_node("node"); c; c = c->next_sibling("node")) ++node_elements;
  const std::vector<std::string> kChildren = {"network", "node", "signal"};
  for (const Node* c = root->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_element) continue;
    std::string_view name = NameOf(c);
    int line = diag_.LineOf(c->name());
    if (name == "network") {
      if (network_line) {
        Err(line, "second <network> (first at line " + std::to_string(network_line) + ")");
        continue;
      }
      network_line = line;
      Network(c, &cfg->network);
    } else if (name == "node") {
      if (++nodes_seen == static_cast<int>(kMaxNodes) + 1)
        Err(line, "too many nodes (at most " + std::to_string(kMaxNodes) + ")");
      NodeConfig node;
      NodeElement(c, node_elements == 1, &node);
      if (nodes_seen <= static_cast<int>(kMaxNodes)) cfg->nodes.push_back(std::move(node));
    } else if (name == "signal") {
      if (++signals_seen == static_cast<int>(kMaxSignals) + 1)
        Err(line, "too many signals (at most " + std::to_string(kMaxSignals) + ")");
      SignalConfig sig;
      SignalRefs refs;
      SignalElement(c, &sig, &refs);
      if (signals_seen <= static_cast<int>(kMaxSignals)) {
        cfg->signals.push_back(std::move(sig));
        refs_.push_back(std::move(refs));
      }
    } else {
      std::string hint = Suggest(name, kChildren);
      if (hint.empty()) hint = " (expected network, node or signal)";
      Err(line, "unknown element <" + std::string(name) + "> in <ccomm>" + hint);
    }
  }
  if (nodes_seen == 0) Err(diag_.LineOf(root->name()), "no <node> defined");
}

void Parser::Network(const Node* n, NetworkConfig* net) {
  Element e(n, {"ethertype", "udp_port", "heartbeat_ms", "peer_timeout_ms", "auth_key_file"},
            &diag_);
  CheckNoText(n, &diag_);
  if (n->first_node(nullptr))
    for (const Node* c = n->first_node(); c; c = c->next_sibling())
      if (c->type() == rapidxml::node_element)
        Err(diag_.LineOf(c->name()), "unknown element <" + std::string(NameOf(c)) +
                                         "> in <network> (it has no child elements)");
  // EtherType values below 0x0600 are 802.3 frame lengths, not protocol numbers.
  Unsigned(e, "ethertype", 0x0600, 0xFFFF, &net->ethertype, /*hex=*/true);
  Unsigned(e, "udp_port", 1, 65535, &net->udp_port);
  bool hb_ok = Unsigned(e, "heartbeat_ms", 1, kMaxHeartbeatMs, &net->heartbeat_ms) ||
               !e.Has("heartbeat_ms");
  bool pt_ok = Unsigned(e, "peer_timeout_ms", 1, kMaxPeerTimeoutMs, &net->peer_timeout_ms) ||
               !e.Has("peer_timeout_ms");
  if (hb_ok && pt_ok && net->peer_timeout_ms < 2 * net->heartbeat_ms) {
    const AttrValue* a = e.Get("peer_timeout_ms");
    Err(a ? a->line : e.line(),
        "peer_timeout_ms " + std::to_string(net->peer_timeout_ms) + " is less than twice " +
            "heartbeat_ms " + std::to_string(net->heartbeat_ms) +
            " (one lost heartbeat would declare the peer dead)");
  }
  if (const AttrValue* a = e.Get("auth_key_file")) {
    if (a->value.empty())
      Err(a->line, "empty auth_key_file (omit it to disable authentication)");
    else if (a->value[0] != '/')
      Err(a->line, "auth_key_file " + Quote(a->value) + " is not an absolute path");
    else
      net->auth_key_file = a->value;
  }
}

void Parser::NodeElement(const Node* n, bool only_node, NodeConfig* node) {
  Element e(n, {"name", "interface", "mac", "ip", "multicast", "transport"}, &diag_);
  node->line = e.line();
  Name(e, "node", &node->name);
  CheckNoText(n, &diag_);
  int realtime_line = 0;
  for (const Node* c = n->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_element) continue;
    int line = diag_.LineOf(c->name());
    if (NameOf(c) != "realtime") {
      std::string hint = Suggest(NameOf(c), {"realtime"});
      if (hint.empty()) hint = " (expected realtime)";
      Err(line, "unknown element <" + std::string(NameOf(c)) + "> in <node>" + hint);
    } else if (realtime_line) {
      Err(line, "second <realtime> in node (first at line " + std::to_string(realtime_line) + ")");
    } else {
      realtime_line = line;
      Realtime(c, &node->realtime);
    }
  }

  bool transport_ok = true;
  if (const AttrValue* a = e.Get("transport")) {
    if (a->value == "raw") {
      node->transport = TransportKind::kRaw;
    } else if (a->value == "udp") {
      node->transport = TransportKind::kUdp;
    } else {
      Err(a->line, "unknown transport " + Quote(a->value) + " (expected raw or udp)");
      transport_ok = false;
    }
  }
  if (const AttrValue* a = e.Get("interface")) {
    const std::string& v = a->value;
    bool ok = !v.empty() && v.size() <= kMaxInterfaceName && v != "." && v != "..";
    for (char c : v)
      if (c == '/' || c == ':' || static_cast<unsigned char>(c) <= ' ' || c == 0x7f) ok = false;
    if (!ok)
      Err(a->line, "invalid interface name " + Quote(v) +
                       " (1 to 15 characters, no '/', ':' or whitespace)");
    else
      node->interface = v;
  }
  if (const AttrValue* a = e.Get("mac")) {
    if (!ParseMac(a->value, node->mac)) {
      Err(a->line, "invalid mac " + Quote(a->value) + " (expected six hex pairs, e.g. 02:00:00:00:00:01)");
    } else if (node->mac[0] & 1) {
      Err(a->line, "mac " + a->value +
                       " is a multicast/broadcast address (omit mac= to send to broadcast)");
    } else if (std::all_of(node->mac, node->mac + 6, [](uint8_t b) { return b == 0; })) {
      Err(a->line, "mac 00:00:00:00:00:00 is not a valid station address");
    } else {
      node->has_mac = true;
    }
  }
  if (const AttrValue* a = e.Get("ip")) {
    uint8_t q[4];
    if (!ParseIpv4(a->value, q)) {
      Err(a->line, "invalid ip " + Quote(a->value) + " (expected an IPv4 address like 10.42.0.1)");
    } else if (q[0] >= 224 || (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0)) {
      Err(a->line, "ip " + a->value + " is not a unicast address");
    } else {
      node->ip = a->value;
    }
  }
  if (const AttrValue* a = e.Get("multicast")) {
    uint8_t q[4];
    if (!ParseIpv4(a->value, q)) {
      Err(a->line, "invalid multicast " + Quote(a->value) +
                       " (expected an IPv4 address like 239.42.0.1)");
    } else if (q[0] < 224 || q[0] > 239) {
      Err(a->line, "multicast " + a->value + " is not in 224.0.0.0/4");
    } else {
      node->multicast = a->value;
    }
  }
  // A node that is alone in the file talks to nobody (shared memory only), so it needs
  // no network settings; Root() passes that in.
  if (transport_ok && !node->name.empty() && !only_node) {
    if (node->transport == TransportKind::kRaw && !e.Has("interface"))
      Err(e.line(), "raw node " + Quote(node->name) +
                        " needs interface= (the network interface its frames use)");
    if (node->transport == TransportKind::kUdp && !e.Has("ip"))
      Err(e.line(), "udp node " + Quote(node->name) +
                        " needs ip= (the IPv4 address its peers send to)");
  }
}

void Parser::Realtime(const Node* n, RealtimeConfig* rt) {
  Element e(n, {"mlockall", "priority", "cpu", "spin_us"}, &diag_);
  CheckNoText(n, &diag_);
  for (const Node* c = n->first_node(); c; c = c->next_sibling())
    if (c->type() == rapidxml::node_element)
      Err(diag_.LineOf(c->name()), "unknown element <" + std::string(NameOf(c)) +
                                       "> in <realtime> (it has no child elements)");
  Bool(e, "mlockall", &rt->mlockall);
  Signed(e, "priority", 1, 99, &rt->priority);
  Signed(e, "cpu", 0, kMaxCpu, &rt->cpu);
  Unsigned(e, "spin_us", 0, kMaxSpinUs, &rt->spin_us);
}

void Parser::SignalElement(const Node* n, SignalConfig* sig, SignalRefs* refs) {
  Element e(n, {"name", "type", "count", "kind", "producer", "consumers", "stale_after_ms",
                "safe_value", "period_ms", "rate_hz", "queue_depth"},
            &diag_);
  sig->line = e.line();
  Name(e, "signal", &sig->name);
  CheckNoText(n, &diag_);
  for (const Node* c = n->first_node(); c; c = c->next_sibling())
    if (c->type() == rapidxml::node_element)
      Err(diag_.LineOf(c->name()), "unknown element <" + std::string(NameOf(c)) +
                                       "> in <signal> (it has no child elements)");

  std::vector<std::string> type_names;
  for (ValueType t : kAllValueTypes) type_names.emplace_back(ValueTypeName(t));
  if (const AttrValue* a = e.Get("type")) {
    if (!ParseValueType(a->value, &sig->type)) {
      Err(a->line, "unknown type " + Quote(a->value) + " (expected " + Join(type_names, ", ") + ")");
      refs->ok = false;
    }
  } else {
    if (!e.Has("type"))
      Err(e.line(), "signal without type= (expected " + Join(type_names, ", ") + ")");
    refs->ok = false;
  }
  if (e.Has("count") && !Unsigned(e, "count", 1, kMaxArrayCount, &sig->count)) refs->ok = false;
  if (refs->ok && sig->value_bytes() > kMaxValueBytes) {
    const AttrValue* a = e.Get("count");
    Err(a ? a->line : e.line(),
        "signal value is " + std::to_string(sig->value_bytes()) + " bytes (count " +
            std::to_string(sig->count) + " x " + std::to_string(ValueTypeSize(sig->type)) +
            "-byte " + ValueTypeName(sig->type) + "); at most " + std::to_string(kMaxValueBytes) +
            " fit in one frame");
    refs->ok = false;
  }
  bool kind_ok = true;
  if (const AttrValue* a = e.Get("kind")) {
    if (a->value == "state") {
      sig->kind = SignalKind::kState;
    } else if (a->value == "event") {
      sig->kind = SignalKind::kEvent;
    } else {
      Err(a->line, "unknown kind " + Quote(a->value) + " (expected state or event)");
      kind_ok = false;
    }
  }
  bool is_event = kind_ok && sig->kind == SignalKind::kEvent;
  bool is_state = kind_ok && sig->kind == SignalKind::kState;

  if (const AttrValue* a = e.Get("producer")) {
    refs->producer = a->value;
    refs->producer_line = a->line;
  } else if (!e.Has("producer")) {
    Err(e.line(), "signal without producer= (every signal has exactly one producer node)");
  }
  if (const AttrValue* a = e.Get("consumers")) {
    // Names separated by commas and/or blanks; "" = local-only.
    std::vector<std::string_view> names;
    if (!SplitList(a->value, &names))
      Err(a->line, "empty name in consumers " + Quote(a->value));
    else
      for (std::string_view name : names) refs->consumers.emplace_back(std::string(name), a->line);
  }

  uint64_t stale = 0;
  if (Unsigned(e, "stale_after_ms", 0, kMaxStaleAfterMs, &stale)) {
    if (is_event) {
      Err(e.Get("stale_after_ms")->line,
          "stale_after_ms applies only to state signals (events are queued, never stale)");
    } else {
      sig->stale_after_ms = static_cast<uint32_t>(stale);
    }
  }

  const AttrValue* period = e.Get("period_ms");
  const AttrValue* rate = e.Get("rate_hz");
  if (period && rate) {
    Err(rate->line, "both period_ms and rate_hz given (use one)");
  } else if (period || rate) {
    const AttrValue* a = period ? period : rate;
    const char* attr = period ? "period_ms" : "rate_hz";
    uint64_t scaled = 0;
    NumResult r = ParseFixed(a->value, 3, &scaled);
    if (r == NumResult::kSyntax) {
      Err(a->line, "invalid " + std::string(attr) + " " + Quote(a->value) +
                       (period ? " (expected milliseconds like 10 or 0.5, resolution 0.001)"
                               : " (expected a frequency like 1000 or 0.5, resolution 0.001)"));
    } else if (r == NumResult::kRange || scaled == 0) {
      Err(a->line, std::string(attr) + " " + a->value + " out of range (expected " +
                       (period ? "0.05..60000)" : "0.017..20000)"));
    } else {
      // period_ms is in microseconds after scaling; rate_hz in millihertz.
      uint64_t us = period ? scaled : (1000000000ull + scaled / 2) / scaled;
      if (us < kMinPeriodUs || us > kMaxPeriodUs) {
        Err(a->line, std::string(attr) + " " + a->value + " gives a period of " +
                         std::to_string(us) + " us (expected 50 us .. 60 s: " +
                         (period ? "period_ms 0.05..60000)" : "rate_hz 0.017..20000)"));
      } else if (is_event) {
        Err(a->line, std::string(attr) +
                         " applies only to state signals (events are sent when written)");
      } else {
        sig->period_us = static_cast<uint32_t>(us);
      }
    }
  }
  if (sig->stale_after_ms != 0 && sig->period_us != 0 &&
      uint64_t{sig->stale_after_ms} * 1000 <= sig->period_us) {
    Err(e.Get("stale_after_ms")->line,
        "stale_after_ms " + std::to_string(sig->stale_after_ms) +
            " is not longer than the period (" + std::to_string(sig->period_us) +
            " us): the signal would go stale between updates");
  }

  if (e.Has("queue_depth")) {
    uint32_t depth = 0;
    if (Unsigned(e, "queue_depth", kMinQueueDepth, kMaxQueueDepth, &depth)) {
      int line = e.Get("queue_depth")->line;
      if (depth & (depth - 1))
        Err(line, "queue_depth " + std::to_string(depth) + " is not a power of two");
      else if (is_state)
        Err(line, "queue_depth applies only to event signals (a state holds one value)");
      else
        sig->queue_depth = depth;
    }
  }

  if (const AttrValue* a = e.Get("safe_value")) {
    // Readers get the safe value before the first value arrives and while the signal
    // is stale (client.cpp); both exist only for state signals.
    if (is_event) {
      Err(a->line, "safe_value applies only to state signals (an event queue has no "
                   "current value to replace)");
    } else if (refs->ok) {
      SafeValue(*a, sig);
    }
  }
}

void Parser::SafeValue(const AttrValue& a, SignalConfig* sig) {
  std::vector<std::string_view> items;
  if (!SplitList(a.value, &items)) {
    Err(a.line, "empty element in safe_value " + Quote(a.value));
    return;
  }
  if (items.empty()) {
    Err(a.line, "empty safe_value");
    return;
  }
  if (items.size() != 1 && items.size() != sig->count) {
    Err(a.line, "safe_value has " + std::to_string(items.size()) + " values; signal has count " +
                    std::to_string(sig->count) + " (give 1 value for all elements or exactly " +
                    std::to_string(sig->count) + ")");
    return;
  }
  const size_t esize = ValueTypeSize(sig->type);
  std::vector<uint8_t> one(esize);
  std::vector<uint8_t> bytes;
  bytes.reserve(sig->value_bytes());
  const char* tname = ValueTypeName(sig->type);
  for (std::string_view item : items) {
    std::string bad;  // "syntax" or "range"
    switch (sig->type) {
      case ValueType::kBool: {
        bool b = false;
        if (!ParseBool(item, &b)) bad = "syntax";
        one[0] = b ? 1 : 0;
        break;
      }
      case ValueType::kInt32:
      case ValueType::kInt64: {
        int64_t x = 0;
        NumResult r = ParseI64(item, &x);
        if (r == NumResult::kSyntax) bad = "syntax";
        else if (r == NumResult::kRange) bad = "range";
        if (sig->type == ValueType::kInt32) {
          if (x < std::numeric_limits<int32_t>::min() || x > std::numeric_limits<int32_t>::max())
            bad = bad.empty() ? "range" : bad;
          int32_t y = static_cast<int32_t>(x);
          std::memcpy(one.data(), &y, 4);
        } else {
          std::memcpy(one.data(), &x, 8);
        }
        break;
      }
      case ValueType::kUint32: {
        uint64_t x = 0;
        NumResult r = item.size() > 1 && item[0] == '-' ? NumResult::kRange : ParseU64(item, &x);
        if (r == NumResult::kSyntax) bad = "syntax";
        else if (r == NumResult::kRange || x > std::numeric_limits<uint32_t>::max()) bad = "range";
        uint32_t y = static_cast<uint32_t>(x);
        std::memcpy(one.data(), &y, 4);
        break;
      }
      case ValueType::kFloat: {
        float f = 0;
        auto r = std::from_chars(item.data(), item.data() + item.size(), f);
        if (r.ptr != item.data() + item.size()) bad = "syntax";
        else if (r.ec == std::errc::result_out_of_range) bad = "range";
        else if (r.ec != std::errc()) bad = "syntax";
        std::memcpy(one.data(), &f, 4);
        break;
      }
      case ValueType::kDouble: {
        double d = 0;
        auto r = std::from_chars(item.data(), item.data() + item.size(), d);
        if (r.ptr != item.data() + item.size()) bad = "syntax";
        else if (r.ec == std::errc::result_out_of_range) bad = "range";
        else if (r.ec != std::errc()) bad = "syntax";
        std::memcpy(one.data(), &d, 8);
        break;
      }
    }
    if (bad == "syntax") {
      const char* expect = sig->type == ValueType::kBool ? "true, false, 1 or 0"
                           : sig->type == ValueType::kFloat || sig->type == ValueType::kDouble
                               ? "a number"
                               : "an integer";
      Err(a.line, "invalid safe_value " + Quote(item) + " for type " + tname + " (expected " +
                      expect + ")");
      return;
    }
    if (bad == "range") {
      Err(a.line, "safe_value " + std::string(item) + " out of range for type " + tname);
      return;
    }
    bytes.insert(bytes.end(), one.begin(), one.end());
  }
  if (items.size() == 1)
    for (uint32_t k = 1; k < sig->count; ++k) bytes.insert(bytes.end(), one.begin(), one.end());
  sig->safe_value = std::move(bytes);
  sig->has_safe_value = true;
}

void Parser::CrossCheck(SystemConfig* cfg) {
  std::vector<std::string> node_names;
  for (size_t i = 0; i < cfg->nodes.size(); ++i) {
    const NodeConfig& n = cfg->nodes[i];
    node_names.push_back(n.name);
    for (size_t j = 0; j < i; ++j) {
      const NodeConfig& m = cfg->nodes[j];
      if (!n.name.empty() && n.name == m.name) {
        Err(n.line, "duplicate node name " + Quote(n.name) + " (first defined at line " +
                        std::to_string(m.line) + ")");
        break;
      }
      if (!n.ip.empty() && n.ip == m.ip)
        Err(n.line, "node " + Quote(n.name) + " has the same ip " + n.ip + " as node " +
                        Quote(m.name) + " (line " + std::to_string(m.line) + ")");
      if (n.has_mac && m.has_mac && std::memcmp(n.mac, m.mac, 6) == 0)
        Err(n.line, "node " + Quote(n.name) + " has the same mac as node " + Quote(m.name) +
                        " (line " + std::to_string(m.line) + ")");
    }
  }
  std::string known = cfg->nodes.empty()       ? " (no nodes defined)"
                      : cfg->nodes.size() <= 8 ? " (nodes: " + Join(node_names, ", ") + ")"
                                               : "";
  auto unknown_node = [&](const std::string& what, const std::string& name) {
    std::string hint = Suggest(name, node_names);
    return "unknown " + what + " node " + Quote(name) + (hint.empty() ? known : hint);
  };

  // Signal names: hash lookups are not needed at this size (<= 4096, once at start-up),
  // but a quadratic scan over 4096 would be 8M compares; sort indices instead.
  std::vector<size_t> order(cfg->signals.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return cfg->signals[a].name < cfg->signals[b].name;
  });
  for (size_t k = 1; k < order.size(); ++k) {
    const SignalConfig& first = cfg->signals[order[k - 1]];
    const SignalConfig& s = cfg->signals[order[k]];
    if (!s.name.empty() && s.name == first.name) {
      // Report against the first definition of the run (the stable sort keeps file order).
      size_t r = k - 1;
      while (r > 0 && cfg->signals[order[r - 1]].name == s.name) --r;
      Err(s.line, "duplicate signal name " + Quote(s.name) + " (first defined at line " +
                      std::to_string(cfg->signals[order[r]].line) + ")");
    }
  }

  std::vector<std::pair<uint32_t, uint32_t>> mixed;  // node pairs already reported
  for (size_t i = 0; i < cfg->signals.size(); ++i) {
    SignalConfig& s = cfg->signals[i];
    const SignalRefs& r = refs_[i];
    int producer = -1;
    if (r.producer_line) {
      producer = cfg->FindNode(r.producer);
      if (producer < 0)
        Err(r.producer_line, unknown_node("producer", r.producer));
      else
        s.producer = static_cast<uint32_t>(producer);
    }
    for (const auto& [name, line] : r.consumers) {
      int c = cfg->FindNode(name);
      if (c < 0) {
        Err(line, unknown_node("consumer", name));
        continue;
      }
      if (c == producer) {
        Err(line, "producer " + Quote(name) + " listed as a consumer of " + Quote(s.name) +
                      " (apps on the producer's node read it from shared memory already)");
        continue;
      }
      if (std::find(s.consumers.begin(), s.consumers.end(), static_cast<uint32_t>(c)) !=
          s.consumers.end()) {
        Err(line, "consumer " + Quote(name) + " listed twice for " + Quote(s.name));
        continue;
      }
      s.consumers.push_back(static_cast<uint32_t>(c));
      // ccommd opens one transport, its own node's, and reaches every peer with it
      // (daemon/transport.h), so nodes that exchange signals must agree on it.
      // Reported once per pair of nodes.
      if (producer < 0) continue;
      const NodeConfig& pn = cfg->nodes[static_cast<size_t>(producer)];
      const NodeConfig& cn = cfg->nodes[static_cast<size_t>(c)];
      if (pn.transport != cn.transport) {
        std::pair<uint32_t, uint32_t> pair(std::min<uint32_t>(producer, c), std::max<uint32_t>(producer, c));
        if (std::find(mixed.begin(), mixed.end(), pair) != mixed.end()) continue;
        mixed.push_back(pair);
        auto tname = [](TransportKind k) { return k == TransportKind::kUdp ? "udp" : "raw"; };
        Err(line, "signal " + Quote(s.name) + " goes from " + tname(pn.transport) + " node " +
                      Quote(pn.name) + " to " + tname(cn.transport) + " node " + Quote(cn.name) +
                      "; nodes that exchange signals need the same transport= (ccommd uses " +
                      "one transport for all its peers)");
      }
    }
  }
}

// Canonical form hashed into SystemConfig::hash (specified in docs/config.md, "Config
// hash"); other implementations must produce the same bytes.
std::string CanonicalForm(const SystemConfig& cfg) {
  std::string s = "ccomm-config 1\n";
  s += "network " + std::to_string(cfg.network.ethertype) + " " +
       std::to_string(cfg.network.udp_port) + "\n";
  for (const NodeConfig& n : cfg.nodes) s += "node " + n.name + "\n";
  for (const SignalConfig& sig : cfg.signals) {
    std::vector<uint32_t> consumers = sig.consumers;
    std::sort(consumers.begin(), consumers.end());  // the set matters, not the order
    std::string list;
    for (uint32_t c : consumers) {
      if (!list.empty()) list += ',';
      list += cfg.nodes[c].name;
    }
    s += "signal " + sig.name + " " + ValueTypeName(sig.type) + " " + std::to_string(sig.count) +
         " " + (sig.kind == SignalKind::kEvent ? "event" : "state") + " " +
         cfg.nodes[sig.producer].name + " " + (list.empty() ? "-" : list) + "\n";
  }
  return s;
}

uint32_t Fnv1a32(const std::string& s) {
  uint32_t h = 2166136261u;
  for (char c : s) {
    h ^= static_cast<uint8_t>(c);
    h *= 16777619u;
  }
  return h;
}

// Comment nodes are kept only to check them (CheckComments); the walk skips them.
constexpr int kXmlFlags = rapidxml::parse_non_destructive | rapidxml::parse_validate_closing_tags |
                          rapidxml::parse_comment_nodes;

// RapidXML recurses once per element level, so a file of a million nested elements would
// overflow the stack. The format nests three levels deep; refuse anything far deeper
// before RapidXML sees it. This scan counts at least the depth RapidXML would reach
// (comments, CDATA, <!...>, <?...?> and quoted attribute values are skipped as RapidXML
// skips them; anything it might misjudge only makes the count higher).
constexpr int kMaxXmlDepth = 32;

size_t FindTooDeep(std::string_view t) {
  int depth = 0;
  size_t i = 0;
  auto skip_past = [&t](size_t from, std::string_view end) {
    size_t e = t.find(end, from);
    return e == std::string_view::npos ? t.size() : e + end.size();
  };
  while ((i = t.find('<', i)) != std::string_view::npos) {
    std::string_view rest = t.substr(i);
    if (rest.substr(0, 4) == "<!--") {
      i = skip_past(i + 4, "-->");
    } else if (rest.substr(0, 9) == "<![CDATA[") {
      i = skip_past(i + 9, "]]>");
    } else if (rest.size() > 1 && (rest[1] == '!' || rest[1] == '?')) {
      i = skip_past(i + 2, ">");
    } else if (rest.size() > 1 && rest[1] == '/') {
      if (depth > 0) --depth;
      i += 2;
    } else {
      size_t j = i + 1;
      char quote = 0;
      for (; j < t.size(); ++j) {
        char c = t[j];
        if (quote) {
          if (c == quote) quote = 0;
        } else if (c == '"' || c == '\'') {
          quote = c;
        } else if (c == '>') {
          break;
        }
      }
      const bool self_closing = j < t.size() && t[j - 1] == '/';
      if (!self_closing && ++depth > kMaxXmlDepth) return i;
      i = j;
    }
  }
  return std::string_view::npos;
}

// Runs the parse with a longjmp target for parse_error_handler (see the top of the file
// for why this is safe). No local of this function changes after setjmp().
bool RunXmlParse(rapidxml::xml_document<char>* doc, char* text, XmlFailure* failure) {
  t_xml_failure = failure;
  if (setjmp(failure->env) != 0) {
    t_xml_failure = nullptr;
    return false;
  }
  doc->parse<kXmlFlags>(text);
  t_xml_failure = nullptr;
  return true;
}

}  // namespace

bool ParseConfig(const std::string& text, const std::string& path, SystemConfig* out,
                 std::string* error) {
  // RapidXML needs a NUL-terminated buffer; parse_non_destructive leaves it unchanged,
  // so names and values point into it and their line numbers can be computed.
  std::vector<char> buf(text.begin(), text.end());
  buf.push_back('\0');
  Parser parser(path, buf.data(), text.size());
  Diagnostics& diag = parser.diag();

  if (text.size() > kMaxFileBytes) {
    diag.Error(0, "file is " + std::to_string(text.size()) + " bytes; at most " +
                      std::to_string(kMaxFileBytes) + " accepted");
  } else if (size_t nul = text.find('\0'); nul != std::string::npos) {
    diag.Error(diag.LineOf(buf.data() + nul), "NUL byte in file (not a text file?)");
  } else if (size_t deep = FindTooDeep(text); deep != std::string::npos) {
    diag.Error(diag.LineOf(buf.data() + deep), "elements nested more than " +
                                                   std::to_string(kMaxXmlDepth) + " levels deep");
  } else {
    rapidxml::xml_document<char> doc;
    XmlFailure failure;
    if (!RunXmlParse(&doc, buf.data(), &failure)) {
      std::string what = failure.what;
      // RapidXML reports a truncated file by what it expected next; say what happened.
      if (failure.where == buf.data() + text.size() && what != "unexpected end of data")
        what = "unexpected end of data (" + what + ")";
      diag.Error(diag.LineOf(failure.where), "XML syntax error: " + what);
    } else {
      SystemConfig cfg;
      cfg.path = path;
      parser.Run(&doc, &cfg);
      if (diag.empty()) {
        cfg.hash = Fnv1a32(CanonicalForm(cfg));
        *out = std::move(cfg);
        if (error) error->clear();
        return true;
      }
    }
  }
  if (error) *error = diag.Render();
  return false;
}

bool LoadConfig(const std::string& path, SystemConfig* out, std::string* error) {
  auto fail = [&](const std::string& what) {
    if (error) *error = path + ": error: " + what;
    return false;
  };
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return fail(std::string("cannot open: ") + std::strerror(errno));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return fail("not a regular file");
  }
  if (static_cast<uint64_t>(st.st_size) > kMaxFileBytes) {
    ::close(fd);
    return fail("file is " + std::to_string(st.st_size) + " bytes; at most " +
                std::to_string(kMaxFileBytes) + " accepted");
  }
  std::string text;
  text.resize(static_cast<size_t>(st.st_size));
  size_t got = 0;
  while (got < text.size()) {
    ssize_t n = ::read(fd, &text[got], text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      int e = errno;
      ::close(fd);
      return fail(std::string("read failed: ") + std::strerror(e));
    }
    if (n == 0) break;  // file shrank while reading
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  text.resize(got);
  return ParseConfig(text, path, out, error);
}

}  // namespace ccomm
