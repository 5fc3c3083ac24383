// SPDX-License-Identifier: Apache-2.0
// The two-node signals.xml of the tests, in text: one builder for the parser's tests
// (config/config_test_util.h: nodes a and b) and the tests of sections read from the file
// (the core's <clock>, extension sections, the bridge's <ros2>: control and planner), so
// that errors are checked by their line. The in-memory model without XML, for the store,
// client and daemon tests below the parser, is testing/test_config.h's TwoNodeConfig.
#pragma once

#include <string>

namespace ccomm {
namespace testing {

/// The two nodes of the document, on lines 2 and 3 (an empty ip: none written).
struct NodePair {
  std::string a, b, ip_a, ip_b;
};
inline const NodePair kNodesAB{"a", "b", "", ""};
inline const NodePair kControlPlanner{"control", "planner", "10.42.0.1", "10.42.0.2"};

/// <ccomm version="1"> on line 1, the two nodes on eth0 on lines 2-3, then `body` (its
/// lines, the last without "\n") from line 4, then </ccomm>.
inline std::string TwoNodeXml(const std::string& body, const NodePair& n = kNodesAB) {
  auto node = [](const std::string& name, const std::string& ip) {
    return "  <node name=\"" + name + "\" interface=\"eth0\"" + (ip.empty() ? "" : " ip=\"" + ip + "\"") + "/>\n";
  };
  return "<ccomm version=\"1\">\n" + node(n.a, n.ip_a) + node(n.b, n.ip_b) + body + "\n</ccomm>\n";
}

/// Control (10.42.0.1) and planner (10.42.0.2) and the state `pos` from control to planner
/// on lines 1-4; then the lines of `more_signals` (each ending in "\n"), then `section`:
/// on line 5 when `more_signals` is empty.
inline std::string TwoNodeDocument(const std::string& section, const std::string& more_signals = "") {
  return TwoNodeXml("  <signal name=\"pos\" type=\"double\" producer=\"control\" consumers=\"planner\"/>\n" +
                        more_signals + "  " + section,
                    kControlPlanner);
}

}  // namespace testing
}  // namespace ccomm
