// SPDX-License-Identifier: Apache-2.0
// A small signals.xml in text, for the tests of sections read from the file (the core's
// <clock>, extension sections, the bridge's <ros2>): errors are checked by their line.
#pragma once

#include <string>

namespace ccomm {
namespace testing {

/// Two nodes, control (10.42.0.1) and planner (10.42.0.2), and the state `pos` from
/// control to planner on lines 1-4; then the lines of `more_signals` (each ending in
/// "\n"), then `section`: on line 5 when `more_signals` is empty.
inline std::string TwoNodeDocument(const std::string& section, const std::string& more_signals = "") {
  return "<ccomm version=\"1\">\n"
         "  <node name=\"control\" interface=\"eth0\" ip=\"10.42.0.1\"/>\n"
         "  <node name=\"planner\" interface=\"eth0\" ip=\"10.42.0.2\"/>\n"
         "  <signal name=\"pos\" type=\"double\" producer=\"control\" consumers=\"planner\"/>\n" +
         more_signals + "  " + section + "\n</ccomm>\n";
}

}  // namespace testing
}  // namespace ccomm
