// SPDX-License-Identifier: Apache-2.0
// The element parsers of signals.xml: each element's attributes checked against what it
// accepts, values parsed and range-checked, every mistake reported with its line.
// parser.cpp: root, network, nodes; parser_signal.cpp: signals and safe values;
// cross_check.cpp: the checks across elements.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "config/config.h"
#include "config/diagnostics.h"
#include "config/text.h"
#include "config/xml_input.h"

namespace ccomm {
namespace config_detail {

// Ranges of the numeric settings (documented in docs/config.md).
constexpr uint32_t kMinPeriodUs = 50;
constexpr uint32_t kMaxPeriodUs = 60u * 1000 * 1000;
constexpr uint32_t kMaxStaleAfterMs = 3600u * 1000;
constexpr uint32_t kMaxHeartbeatMs = 10000;
constexpr uint32_t kMaxPeerTimeoutMs = 60000;
constexpr uint32_t kMinSummaryMs = 100, kMaxSummaryMs = 60000;
constexpr uint32_t kMaxSpinUs = 100000;
// Send on the cycle: the cycle divides one second (50 us .. 1 s); the lead covers building
// the frames and the ETF qdisc's delta.
constexpr uint32_t kMinSendCycleUs = 50, kMaxSendCycleUs = 1000000;
constexpr uint32_t kMinSendLeadUs = 20, kDefaultSendLeadUs = 300;
constexpr int kMaxCpu = 1023;  // CPU_SETSIZE - 1
constexpr uint32_t kMinQueueDepth = 2;
constexpr uint32_t kMaxQueueDepth = 65536;
constexpr size_t kMaxInterfaceName = 15;  // IFNAMSIZ - 1

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


/// Reports text inside an element (everything in this format is an attribute).
void CheckNoText(const Node* parent, Diagnostics* diag);
/// Reports child elements of an element that has attributes only (and no text).
void CheckAttributesOnly(const Node* parent, Diagnostics* diag);
/// Whether <name> in <ccomm> is an extension section (outline.h: kExtensionSections).
bool IsExtensionSection(std::string_view name);
/// Reports "--" inside comments (xmllint and editors reject them).
void CheckComments(const Node* parent, Diagnostics* diag);

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
  void SendCycle(const Element& e, RealtimeConfig* rt);
  void SignalElement(const Node* n, SignalConfig* sig, SignalRefs* refs);
  void SafeValue(const AttrValue& a, SignalConfig* sig);
  void CrossCheck(SystemConfig* cfg);
  void ExtensionElement(const Node* n, SectionElement* out);  // extension_section.cpp
  void ClockElement(const Node* n, ClockConfig* out);   // clock_section.cpp
  void CrossCheckClock(SystemConfig* cfg);              // clock_section.cpp

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

}  // namespace config_detail
}  // namespace ccomm
