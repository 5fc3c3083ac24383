// SPDX-License-Identifier: Apache-2.0
// The mapping file of ccomm-fmu (docs/integrations/fmi.md, "Mapping"): one line per FMU
// variable whose signal has another name, a freshness flag, or that stays unconnected.
//   <fmu variable> = <signal>          input, output or tunable parameter <-> that signal
//   <fmu variable> = fresh(<signal>)   Boolean input: 1 while <signal> is fresh, else 0
//   <fmu variable> = -                 not connected (keeps its start value / not written)
// '#' starts a comment. Variables not listed map to the signal of their own name.
#ifndef CCOMM_FMU_MAPPING_H
#define CCOMM_FMU_MAPPING_H
#include <string>
#include <vector>

namespace ccomm::fmu {

struct MappingLine {
  std::string variable;
  std::string signal;  // empty: not connected
  bool freshness = false;
  int line = 0;
};

// Parses `path`; false with "path:line: message" in `error`.
bool LoadMapping(const std::string& path, std::vector<MappingLine>* out, std::string* error);
// The same on `text` already read (`path` names it in messages).
bool ParseMapping(const std::string& path, const std::string& text, std::vector<MappingLine>* out,
                  std::string* error);

}  // namespace ccomm::fmu
#endif
