// SPDX-License-Identifier: Apache-2.0
#include "mapping.h"

#include <set>

#include "model_description.h"

namespace ccomm::fmu {
namespace {
std::string Trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return std::string();
  size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}
bool IsName(const std::string& s) {  // FMI names may hold '.', '[', ']', ',' (FMI 2.0 arrays)
  if (s.empty()) return false;
  for (char ch : s)
    if (ch == ' ' || ch == '\t' || ch == '=' || ch == '#' || ch == '(' || ch == ')') return false;
  return true;
}
}  // namespace

bool LoadMapping(const std::string& path, std::vector<MappingLine>* out, std::string* error) {
  std::string text;
  if (!ReadFile(path, &text, error)) return false;
  return ParseMapping(path, text, out, error);
}

bool ParseMapping(const std::string& path, const std::string& text, std::vector<MappingLine>* out,
                  std::string* error) {
  std::set<std::string> seen;
  int line_no = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    line = Trim(line);
    if (line.empty()) continue;
    auto fail = [&](const std::string& m) {
      *error = path + ":" + std::to_string(line_no) + ": " + m;
      return false;
    };
    size_t eq = line.find('=');
    if (eq == std::string::npos) return fail("expected '<fmu variable> = <signal>', got \"" + line + "\"");
    MappingLine m;
    m.line = line_no;
    m.variable = Trim(line.substr(0, eq));
    std::string rhs = Trim(line.substr(eq + 1));
    if (!IsName(m.variable)) return fail("\"" + m.variable + "\" is not an FMU variable name");
    if (rhs.compare(0, 6, "fresh(") == 0 && rhs.size() > 7 && rhs.back() == ')') {
      m.freshness = true;
      rhs = Trim(rhs.substr(6, rhs.size() - 7));
    }
    if (rhs == "-" && !m.freshness) {
      rhs.clear();
    } else if (!IsName(rhs) || rhs == "-") {
      return fail("\"" + rhs + "\" is not a signal name (or fresh(<signal>), or - for not connected)");
    }
    m.signal = rhs;
    if (!seen.insert(m.variable).second) return fail("variable \"" + m.variable + "\" mapped twice");
    out->push_back(m);
  }
  return true;
}

}  // namespace ccomm::fmu
