// SPDX-License-Identifier: Apache-2.0
// <clock>: linuxptp between the boards (docs/config.md, docs/design.md "Time").
//   <clock domain="0" grandmaster="control, planner" timestamping="software"
//          sync_interval_log="-3" socket="/var/run/ptp4l"/>
// Local policy like <ros2>: not part of the configuration hash.
#include "config/parser.h"

namespace ccomm {
namespace config_detail {

void Parser::ClockElement(const Node* n, ClockConfig* out) {
  Element e(n, {"domain", "grandmaster", "timestamping", "sync_interval_log", "socket"}, &diag_);
  out->present = true;
  out->line = e.line();
  CheckAttributesOnly(n, &diag_);
  Unsigned(e, "domain", 0, 127, &out->domain);  // 128..255 are reserved by IEEE 1588
  if (const AttrValue* a = e.Get("grandmaster")) {
    std::vector<std::string_view> items;
    if (a->value.empty() || !SplitList(a->value, &items))
      Err(a->line, "empty name in grandmaster " + Quote(a->value) + " (the nodes that may be grandmaster)");
    else
      for (std::string_view s : items) out->grandmasters.emplace_back(s);
  } else if (!e.Has("grandmaster")) {
    Err(e.line(), "<clock> without grandmaster= (the node, or nodes best first, that may be grandmaster)");
  }
  if (const AttrValue* a = e.Get("timestamping")) {
    if (a->value == "hardware") out->hardware = true;
    else if (a->value != "software")
      Err(a->line, "timestamping " + Quote(a->value) + " is not 'software' or 'hardware'");
  }
  Signed(e, "sync_interval_log", -7, 4, &out->sync_interval_log);
  if (const AttrValue* a = e.Get("socket")) {
    if (a->value.empty() || a->value[0] != '/' || a->value.size() > 100)
      Err(a->line, "socket " + Quote(a->value) + " is not an absolute path of at most 100 characters");
    else
      out->socket = a->value;
  }
}

void Parser::CrossCheckClock(SystemConfig* cfg) {
  const ClockConfig& c = cfg->clock;
  if (!c.present) return;
  for (size_t i = 0; i < c.grandmasters.size(); ++i) {
    if (cfg->FindNode(c.grandmasters[i]) < 0)
      Err(c.line, "<clock> grandmaster: unknown node " + Quote(c.grandmasters[i]));
    for (size_t j = 0; j < i; ++j)
      if (c.grandmasters[j] == c.grandmasters[i])
        Err(c.line, "<clock> grandmaster: node " + Quote(c.grandmasters[i]) + " given twice");
  }
}

}  // namespace config_detail
}  // namespace ccomm
