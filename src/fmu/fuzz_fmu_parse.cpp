// SPDX-License-Identifier: Apache-2.0
// libFuzzer target of ccomm-fmu's parsers: the first byte picks modelDescription.xml (even)
// or a mapping file (odd); either accepts the rest or explains with a file:line message.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "mapping.h"
#include "model_description.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  std::string error;
  bool ok;
  if (data[0] % 2 == 0) {
    ccomm::fmu::ModelDescription md;
    ok = ccomm::fmu::ParseModelDescription("md.xml", text, &md, &error);
    if (ok && md.fmi_major != 2 && md.fmi_major != 3) std::abort();
  } else {
    std::vector<ccomm::fmu::MappingLine> lines;
    ok = ccomm::fmu::ParseMapping("f.map", text, &lines, &error);
  }
  if (!ok && error.find(".xml:") == std::string::npos && error.find(".map:") == std::string::npos) std::abort();
  return 0;
}
