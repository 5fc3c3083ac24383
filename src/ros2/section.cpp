// SPDX-License-Identifier: Apache-2.0
// <ros2> in signals.xml (section.h): each attribute parsed and range-checked, then the
// checks against the rest of the file, every mistake reported with its line.
#include "section.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <utility>

namespace ccomm_ros2 {
namespace {

using ccomm::ConfigOutline;
using ccomm::SectionAttribute;
using ccomm::SectionElement;

std::string Quote(const std::string& s) { return ccomm::ConfigQuote(s); }

class Checker {
 public:
  explicit Checker(const ConfigOutline& cfg) : cfg_(cfg) {}

  void Err(int line, std::string message) { errors_.emplace_back(line, std::move(message)); }

  void Section(const SectionElement& e, Ros2Section* out) {
    out->line = e.line;
    static const char* const kAttributes[] = {"node", "namespace", "domain", "publish", "subscribe"};
    for (const SectionAttribute& a : e.attributes)
      if (std::find_if(std::begin(kAttributes), std::end(kAttributes),
                       [&](const char* k) { return a.name == k; }) == std::end(kAttributes))
        Err(a.line, "unknown attribute " + Quote(a.name) +
                        " on <ros2> (expected node, namespace, domain, publish, subscribe)");
    for (const SectionElement& c : e.children)
      Err(c.line, "unknown element <" + c.name + "> in <ros2> (it has attributes only)");
    if (const SectionAttribute* a = e.Find("node")) {
      out->node = a->value;
      // An empty name is no node; the cross-check skips sections without one.
      if (a->value.empty()) Err(a->line, "<ros2> with an empty node= (the node ccomm-ros2 runs on)");
    } else {
      Err(e.line, "<ros2> without node= (the node ccomm-ros2 runs on)");
    }
    if (const SectionAttribute* a = e.Find("namespace")) {
      std::string ns = a->value;
      while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
      while (!ns.empty() && ns.back() == '/') ns.pop_back();
      if (!IsRosNamespace(ns))
        Err(a->line, "namespace " + Quote(a->value) + " is not a ROS 2 name (tokens of A-Z a-z "
                     "0-9 _ separated by '/', none starting with a digit)");
      out->ros_namespace = ns;
    }
    if (const SectionAttribute* a = e.Find("domain")) {
      const std::string& v = a->value;
      bool digits = !v.empty() && std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; });
      const std::string range = "0.." + std::to_string(kMaxRosDomain);
      if (!digits) {
        Err(a->line, "invalid domain " + Quote(v) + " (expected an integer " + range + ")");
      } else if (v.size() > 3 || std::strtoul(v.c_str(), nullptr, 10) > kMaxRosDomain) {
        Err(a->line, "domain " + v + " out of range (expected " + range + ")");
      } else {
        out->domain = static_cast<uint32_t>(std::strtoul(v.c_str(), nullptr, 10));
        out->has_domain = true;
      }
    }
    auto list = [&](const char* attr, std::vector<std::string>* names) {
      const SectionAttribute* a = e.Find(attr);
      if (!a) return false;
      if (!a->value.empty() && !ccomm::SplitConfigList(a->value, names)) {
        names->clear();
        Err(a->line, std::string("empty name in ") + attr + " " + Quote(a->value));
      }
      return true;
    };
    out->publish_given = list("publish", &out->publish);
    list("subscribe", &out->subscribe);
  }

  // The checks against the rest of the file (and the other <ros2> sections).
  void CrossCheck(const std::vector<Ros2Section>& all) {
    for (size_t i = 0; i < all.size(); ++i) {
      const Ros2Section& r = all[i];
      if (r.node.empty()) continue;
      bool repeated = false;
      for (size_t j = 0; j < i && !repeated; ++j)
        if (all[j].node == r.node) {
          Err(r.line, "second <ros2> for node " + Quote(r.node) + " (first at line " +
                          std::to_string(all[j].line) + ")");
          repeated = true;
        }
      if (repeated) continue;
      if (!cfg_.HasNode(r.node)) {
        Err(r.line, "<ros2> for unknown node " + Quote(r.node));
        continue;
      }
      auto check = [&](const std::string& name, bool subscribe) {
        const char* what = subscribe ? "subscribe" : "publish";
        const ccomm::OutlineSignal* s = cfg_.FindSignal(name);
        if (!s) {
          Err(r.line, std::string("<ros2> ") + what + ": unknown signal " + Quote(name));
          return;
        }
        bool produced = s->producer == r.node;
        bool consumed = std::find(s->consumers.begin(), s->consumers.end(), r.node) != s->consumers.end();
        if (subscribe && !produced)
          Err(r.line, "<ros2> subscribe: signal " + Quote(name) + " is produced by node " +
                          Quote(s->producer) + ", not " + Quote(r.node) +
                          " (only a producer's values can come from ROS 2)");
        else if (!subscribe && !produced && !consumed)
          Err(r.line, "<ros2> publish: signal " + Quote(name) + " is neither produced nor consumed "
                      "on node " + Quote(r.node) + " (add it to its consumers=)");
        if (!IsRosToken(name))
          Err(r.line, "<ros2> " + std::string(what) + ": signal name " + Quote(name) +
                          " is not a ROS 2 topic name token (A-Z a-z 0-9 _, not starting with a digit)");
      };
      for (const std::string& s : r.publish) check(s, false);
      for (const std::string& s : r.subscribe) {
        check(s, true);
        if (std::find(r.publish.begin(), r.publish.end(), s) != r.publish.end())
          Err(r.line, "<ros2>: signal " + Quote(s) + " is in both publish and subscribe (it would loop)");
      }
    }
  }

  // Every message, in line order (equal lines in the order found).
  std::string Render() {
    std::stable_sort(errors_.begin(), errors_.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::string out;
    for (const auto& e : errors_) {
      if (!out.empty()) out += '\n';
      out += ccomm::ConfigError(cfg_.path, e.first, e.second);
    }
    return out;
  }
  bool ok() const { return errors_.empty(); }

 private:
  const ConfigOutline& cfg_;
  std::vector<std::pair<int, std::string>> errors_;
};

}  // namespace

bool IsRosToken(const std::string& s) {
  if (s.empty() || (s[0] >= '0' && s[0] <= '9')) return false;
  for (char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'))
      return false;
  return true;
}

bool IsRosNamespace(const std::string& ns) {
  for (size_t start = 0; !ns.empty() && start <= ns.size();) {
    size_t slash = ns.find('/', start);
    if (slash == std::string::npos) slash = ns.size();
    if (!IsRosToken(ns.substr(start, slash - start))) return false;
    start = slash + 1;
  }
  return true;
}

bool ReadRos2Sections(const ConfigOutline& cfg, std::vector<Ros2Section>* out, std::string* errors) {
  Checker check(cfg);
  std::vector<Ros2Section> sections;
  for (const SectionElement& e : cfg.sections) {
    if (e.name != "ros2") continue;
    Ros2Section r;
    check.Section(e, &r);
    sections.push_back(std::move(r));
  }
  check.CrossCheck(sections);
  if (!check.ok()) {
    if (errors) *errors = check.Render();
    return false;
  }
  *out = std::move(sections);
  if (errors) errors->clear();
  return true;
}

int CheckConfig(const std::string& path) {
  ccomm::ConfigOutline cfg;
  std::vector<Ros2Section> sections;
  std::string err;
  if (!ccomm::LoadConfigOutline(path, &cfg, &err) || !ReadRos2Sections(cfg, &sections, &err)) {
    fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }
  printf("%s: ok (%zu <ros2> section%s)\n", path.c_str(), sections.size(), sections.size() == 1 ? "" : "s");
  return 0;
}

}  // namespace ccomm_ros2
