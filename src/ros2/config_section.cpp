// SPDX-License-Identifier: Apache-2.0
// The <ros2> element of signals.xml (parsed and checked by the configuration parser, the
// same one `ccommd --check` runs): the bridge's settings for one node, under whatever the
// command line set explicitly.
#include <cstdio>
#include <string>

#include "bridge.h"
#include "config/config.h"

namespace ccomm_ros2 {

bool ApplyConfigSection(Options* o, const std::string& node) {
  if (o->config_path.empty()) return true;
  ccomm::SystemConfig cfg;
  std::string err;
  if (!ccomm::LoadConfig(o->config_path, &cfg, &err)) {
    fprintf(stderr, "%sccomm-ros2: %s is not a valid configuration (see above; ccommd --check %s)\n",
            err.c_str(), o->config_path.c_str(), o->config_path.c_str());
    return false;
  }
  for (const ccomm::Ros2Config& r : cfg.ros2) {
    if (r.node != node) continue;
    if (!o->namespace_given) o->ros_namespace = r.ros_namespace;
    if (!o->domain_given && r.has_domain) o->domain = static_cast<int>(r.domain);
    if (!o->publish_given && r.publish_given) {
      o->publish_given = true;
      o->publish = r.publish;
    }
    if (o->subscribe.empty()) o->subscribe = r.subscribe;
    if (o->verbose)
      fprintf(stderr, "ccomm-ros2: settings of %s:%d (<ros2 node=\"%s\">)\n", o->config_path.c_str(),
              r.line, node.c_str());
    return true;
  }
  return true;
}

}  // namespace ccomm_ros2
