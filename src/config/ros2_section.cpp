// SPDX-License-Identifier: Apache-2.0
// <ros2>: what ccomm-ros2 bridges on one node (docs/config.md, docs/integrations/ros2.md).
//   <ros2 node="planner" namespace="robot1" domain="7"
//         publish="pos, joints" subscribe="setpoint, cmd"/>
// Local policy like <realtime>: not part of the configuration hash.
#include "config/parser.h"

namespace ccomm {
namespace config_detail {
namespace {

constexpr uint32_t kMaxRosDomain = 232;  // ROS 2's limit (DDS derives UDP ports from it)

// A ROS 2 name token: letters, digits and '_', not starting with a digit.
bool RosToken(std::string_view s) {
  if (s.empty() || (s[0] >= '0' && s[0] <= '9')) return false;
  for (char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'))
      return false;
  return true;
}

}  // namespace

void Parser::Ros2Element(const Node* n, Ros2Config* out) {
  Element e(n, {"node", "namespace", "domain", "publish", "subscribe"}, &diag_);
  out->line = e.line();
  CheckAttributesOnly(n, &diag_);
  if (const AttrValue* a = e.Get("node")) out->node = a->value;
  else if (!e.Has("node")) Err(e.line(), "<ros2> without node= (the node ccomm-ros2 runs on)");
  if (const AttrValue* a = e.Get("namespace")) {
    std::string ns = a->value;  // stored without leading/trailing '/'
    while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
    while (!ns.empty() && ns.back() == '/') ns.pop_back();
    std::vector<std::string_view> tokens;
    size_t start = 0;
    bool ok = true;
    while (!ns.empty() && start <= ns.size()) {
      size_t slash = ns.find('/', start);
      if (slash == std::string::npos) slash = ns.size();
      ok = ok && RosToken(std::string_view(ns).substr(start, slash - start));
      start = slash + 1;
    }
    if (!ok)
      Err(a->line, "namespace " + Quote(a->value) + " is not a ROS 2 name (tokens of A-Z a-z "
                   "0-9 _ separated by '/', none starting with a digit)");
    out->ros_namespace = ns;
  }
  out->has_domain = Unsigned(e, "domain", 0, kMaxRosDomain, &out->domain);
  auto list = [&](const char* attr, std::vector<std::string>* names) {
    const AttrValue* a = e.Get(attr);
    if (!a) return false;
    std::vector<std::string_view> items;
    if (!a->value.empty() && !SplitList(a->value, &items)) {
      Err(a->line, std::string("empty name in ") + attr + " " + Quote(a->value));
      return true;
    }
    for (std::string_view s : items) names->emplace_back(s);
    return true;
  };
  out->publish_given = list("publish", &out->publish);
  list("subscribe", &out->subscribe);
}

void Parser::CrossCheckRos2(SystemConfig* cfg) {
  for (size_t i = 0; i < cfg->ros2.size(); ++i) {
    const Ros2Config& r = cfg->ros2[i];
    for (size_t j = 0; j < i; ++j)
      if (!r.node.empty() && cfg->ros2[j].node == r.node)
        Err(r.line, "second <ros2> for node " + Quote(r.node) + " (first at line " +
                        std::to_string(cfg->ros2[j].line) + ")");
    if (r.node.empty()) continue;
    int node = cfg->FindNode(r.node);
    if (node < 0) {
      Err(r.line, "<ros2> for unknown node " + Quote(r.node));
      continue;
    }
    auto check = [&](const std::string& name, bool subscribe) {
      int id = cfg->FindSignal(name);
      const char* what = subscribe ? "subscribe" : "publish";
      if (id < 0) {
        Err(r.line, std::string("<ros2> ") + what + ": unknown signal " + Quote(name));
        return;
      }
      const SignalConfig& s = cfg->signals[static_cast<size_t>(id)];
      bool produced = s.producer == static_cast<uint32_t>(node);
      bool consumed = false;
      for (uint32_t c : s.consumers) consumed |= c == static_cast<uint32_t>(node);
      if (subscribe && !produced)
        Err(r.line, "<ros2> subscribe: signal " + Quote(name) + " is produced by node " +
                        Quote(cfg->nodes[s.producer].name) + ", not " + Quote(r.node) +
                        " (only a producer's values can come from ROS 2)");
      else if (!subscribe && !produced && !consumed)
        Err(r.line, "<ros2> publish: signal " + Quote(name) + " is neither produced nor consumed "
                    "on node " + Quote(r.node) + " (add it to its consumers=)");
      if (!RosToken(name))
        Err(r.line, "<ros2> " + std::string(what) + ": signal name " + Quote(name) +
                        " is not a ROS 2 topic name token (A-Z a-z 0-9 _, not starting with a digit)");
    };
    for (const std::string& s : r.publish) check(s, false);
    for (const std::string& s : r.subscribe) {
      check(s, true);
      for (const std::string& p : r.publish)
        if (p == s) Err(r.line, "<ros2>: signal " + Quote(s) + " is in both publish and subscribe (it would loop)");
    }
  }
}

}  // namespace config_detail
}  // namespace ccomm
