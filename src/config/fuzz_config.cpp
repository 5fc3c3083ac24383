// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: parse arbitrary bytes as signals.xml. Checks that the parser (and the
// longjmp out of RapidXML's error handler) never touches memory it should not (ASan),
// that a rejected input always gets at least one message, and that an accepted one
// satisfies the limits LoadConfig promises.
#include <cstdlib>
#include <string>

#include "config/config.h"

namespace {
void Check(bool ok) {
  if (!ok) std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ccomm::SystemConfig cfg;
  std::string error;
  if (!ccomm::ParseConfig(text, "fuzz.xml", &cfg, &error)) {
    Check(error.rfind("fuzz.xml", 0) == 0);
    return 0;
  }
  Check(error.empty());
  Check(!cfg.nodes.empty() && cfg.nodes.size() <= ccomm::kMaxNodes);
  Check(cfg.signals.size() <= ccomm::kMaxSignals);
  for (const ccomm::SignalConfig& s : cfg.signals) {
    Check(s.producer < cfg.nodes.size());
    for (uint32_t c : s.consumers) Check(c < cfg.nodes.size() && c != s.producer);
    Check(s.count >= 1 && s.count <= ccomm::kMaxArrayCount);
    Check(s.value_bytes() <= ccomm::kMaxValueBytes);
    Check(!s.has_safe_value || s.safe_value.size() == s.value_bytes());
    Check(s.queue_depth >= 2 && (s.queue_depth & (s.queue_depth - 1)) == 0);
  }
  return 0;
}
