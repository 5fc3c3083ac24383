// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: arbitrary bytes as signals.xml, through the core parser and then the
// bridge's <ros2> reader (section.cpp). Its promises, checked on every input: no crash,
// leak or out-of-bounds read (ASan/UBSan); it accepts or explains with FILE:LINE lines;
// and what it accepts is what the bridge relies on without re-checking.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "config/public/outline.h"
#include "section.h"

namespace {

void Check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ccomm::ConfigOutline cfg;
  std::string error;
  if (!ccomm::ParseConfigOutline(text, "fuzz.xml", &cfg, &error)) return 0;  // fuzz_config's
  for (const ccomm::SectionElement& e : cfg.sections) Check(e.line > 0);
  std::vector<ccomm_ros2::Ros2Section> sections;
  if (!ccomm_ros2::ReadRos2Sections(cfg, &sections, &error)) {
    // Every line of the explanation names the file and a line of it.
    size_t at = 0;
    while (at < error.size()) {
      Check(error.compare(at, 9, "fuzz.xml:") == 0 && error[at + 9] >= '1' && error[at + 9] <= '9');
      size_t nl = error.find('\n', at);
      at = nl == std::string::npos ? error.size() : nl + 1;
    }
    Check(!error.empty());
    return 0;
  }
  Check(error.empty());
  for (size_t i = 0; i < sections.size(); ++i) {
    const ccomm_ros2::Ros2Section& r = sections[i];
    Check(cfg.HasNode(r.node));
    for (size_t j = 0; j < i; ++j) Check(sections[j].node != r.node);  // one per node
    Check(r.domain <= ccomm_ros2::kMaxRosDomain);
    Check(ccomm_ros2::IsRosNamespace(r.ros_namespace));
    for (const std::string& s : r.publish) {
      const ccomm::OutlineSignal* sig = cfg.FindSignal(s);
      Check(sig && ccomm_ros2::IsRosToken(s));
      Check(sig->producer == r.node ||
            std::find(sig->consumers.begin(), sig->consumers.end(), r.node) != sig->consumers.end());
    }
    for (const std::string& s : r.subscribe) {
      const ccomm::OutlineSignal* sig = cfg.FindSignal(s);
      Check(sig && sig->producer == r.node && ccomm_ros2::IsRosToken(s));
      Check(std::find(r.publish.begin(), r.publish.end(), s) == r.publish.end());
    }
  }
  return 0;
}
