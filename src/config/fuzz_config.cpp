// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: parse arbitrary bytes as signals.xml. The parser's promises, checked
// on every input: it never crashes, leaks, hangs or reads out of bounds (ASan/UBSan, the
// RapidXML longjmp error path included); it either accepts or explains; and whatever it
// accepts satisfies every limit and cross reference that ccommd and the segment layout
// rely on without re-checking (config.h), and has a stable hash.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "config/config.h"

using namespace ccomm;

namespace {

void Check(bool ok) {
  if (!ok) std::abort();
}

void CheckAccepted(const SystemConfig& c) {
  Check(!c.nodes.empty() && c.nodes.size() <= kMaxNodes);
  Check(c.signals.size() <= kMaxSignals);
  for (size_t i = 0; i < c.nodes.size(); ++i) {
    const NodeConfig& n = c.nodes[i];
    Check(!n.name.empty() && n.name.size() <= kMaxNameLength);
    Check(c.FindNode(n.name) == static_cast<int>(i));  // names are unique
    Check(n.realtime.priority >= 0 && n.realtime.priority <= 99);
    Check(n.history == 0 || (n.history >= 2 && n.history <= 65536 && (n.history & (n.history - 1)) == 0));
  }
  for (size_t i = 0; i < c.signals.size(); ++i) {
    const SignalConfig& s = c.signals[i];
    Check(!s.name.empty() && s.name.size() <= kMaxNameLength);
    Check(c.FindSignal(s.name) == static_cast<int>(i));
    Check(ValueTypeName(s.type) != nullptr);
    Check(s.count >= 1 && s.count <= kMaxArrayCount);
    Check(s.value_bytes() >= 1 && s.value_bytes() <= kMaxValueBytes);
    Check(s.producer < c.nodes.size());
    for (size_t k = 0; k < s.consumers.size(); ++k) {
      Check(s.consumers[k] < c.nodes.size() && s.consumers[k] != s.producer);
      for (size_t j = 0; j < k; ++j) Check(s.consumers[j] != s.consumers[k]);
    }
    Check(!s.has_safe_value || s.safe_value.size() == s.value_bytes());
    Check(s.queue_depth >= 2 && (s.queue_depth & (s.queue_depth - 1)) == 0);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  SystemConfig cfg;
  std::string error;
  const bool ok = ParseConfig(text, "fuzz.xml", &cfg, &error);
  if (!ok) {
    // Rejected: at least one "fuzz.xml:LINE: error: ..." line.
    Check(error.compare(0, 9, "fuzz.xml:") == 0);
    return 0;
  }
  Check(error.empty());
  CheckAccepted(cfg);
  // Same input, same result: the hash is what both ends of a link compare.
  SystemConfig again;
  std::string error2;
  Check(ParseConfig(text, "other.xml", &again, &error2));
  Check(again.hash == cfg.hash && again.signals.size() == cfg.signals.size());
  return 0;
}
