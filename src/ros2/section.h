// SPDX-License-Identifier: Apache-2.0
// The <ros2> sections of signals.xml, read and checked by the bridge that owns them: the
// core parser keeps them as element trees (config/public/outline.h) and checks their structure
// only. No DDS here: `ccomm-ros2 --check` and the unit test need none.
//   <ros2 node="planner" namespace="robot1" domain="7"
//         publish="pos, joints" subscribe="setpoint, cmd"/>
// docs/config.md ("<ros2>"), docs/integrations/ros2.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "config/public/outline.h"

namespace ccomm_ros2 {

// The settings of the bridge on one node.
struct Ros2Section {
  std::string node;                   // the node the bridge runs on
  std::string ros_namespace = "ccomm";  // without leading/trailing '/'
  uint32_t domain = 0;                // ROS 2 domain id 0..232
  bool has_domain = false;
  bool publish_given = false;         // false: every signal the node consumes
  std::vector<std::string> publish;   // ccomm -> ROS 2
  std::vector<std::string> subscribe; // ROS 2 -> ccomm (signals the node produces)
  int line = 0;
};

constexpr uint32_t kMaxRosDomain = 232;  // ROS 2's limit (DDS derives UDP ports from it)

/// A ROS 2 name token (a topic name's part, e.g. a signal name): letters, digits and '_',
/// not starting with a digit.
bool IsRosToken(const std::string& s);
/// A namespace without leading/trailing '/': empty, or tokens separated by single '/'.
bool IsRosNamespace(const std::string& ns);

/// Reads and checks every <ros2> section of `cfg` (at most one per node, every signal
/// named known and usable on that node). False with every mistake in `errors`, one
/// "FILE:LINE: error: MESSAGE" line each, in line order.
bool ReadRos2Sections(const ccomm::ConfigOutline& cfg, std::vector<Ros2Section>* out,
                      std::string* errors);

/// `ccomm-ros2 --check`: the file as `ccommd --check` reads it, then every <ros2> section;
/// "FILE: ok (...)" on stdout, or every error (FILE:LINE) on stderr. The exit status: 0
/// valid, 1 not.
int CheckConfig(const std::string& path);

}  // namespace ccomm_ros2
