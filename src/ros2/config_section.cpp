// SPDX-License-Identifier: Apache-2.0
// The <ros2> element of signals.xml for the bridge's node: the file read with the parser
// `ccommd --check` runs (config/public/outline.h), the <ros2> sections checked here (section.h),
// their settings applied under whatever the command line set explicitly.
#include <cstdio>
#include <string>
#include <vector>

#include "bridge.h"
#include "config/public/outline.h"
#include "section.h"

namespace ccomm_ros2 {

bool ApplyConfigSection(Options* o, const std::string& node) {
  if (o->config_path.empty()) return true;
  ccomm::ConfigOutline cfg;
  std::vector<Ros2Section> sections;
  std::string err;
  if (!ccomm::LoadConfigOutline(o->config_path, &cfg, &err) || !ReadRos2Sections(cfg, &sections, &err)) {
    fprintf(stderr, "%s\nccomm-ros2: %s is not a valid configuration (see above; ccomm-ros2 --check --config %s)\n",
            err.c_str(), o->config_path.c_str(), o->config_path.c_str());
    return false;
  }
  for (const Ros2Section& r : sections) {
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
