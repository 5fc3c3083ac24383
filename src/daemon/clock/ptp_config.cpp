// SPDX-License-Identifier: Apache-2.0
#include "daemon/clock/ptp_config.h"

namespace ccomm {

std::string Ptp4lConfig(const SystemConfig& cfg, uint32_t node, std::string* error) {
  const ClockConfig& c = cfg.clock;
  if (!c.present) {
    *error = cfg.path + ": no <clock> section (see docs/config.md): nothing to configure ptp4l with";
    return {};
  }
  const NodeConfig& n = cfg.nodes[node];
  // ptp4l runs PTP on a named port; without one its file has an empty "[]" section, which
  // ptp4l refuses ("could not parse port name") only when the unit starts it.
  if (n.interface.empty()) {
    *error = cfg.path + ":" + std::to_string(n.line) + ": node '" + n.name +
             "' has no interface=: ptp4l needs the interface to run PTP on (docs/config.md, <clock>)";
    return {};
  }
  // Grandmaster candidates in the order given: priority1 100, 101, ... (lower wins the
  // best master clock algorithm); every other node never becomes master.
  int rank = -1;
  for (size_t i = 0; i < c.grandmasters.size(); ++i)
    if (c.grandmasters[i] == n.name) rank = static_cast<int>(i);
  std::string s;
  s += "# ptp4l configuration of node '" + n.name + "', written by ccommd --clock-config from\n";
  s += "# " + cfg.path + " (<clock>, line " + std::to_string(c.line) + "). Edit <clock>, not this file.\n";
  s += "[global]\n";
  s += "domainNumber " + std::to_string(c.domain) + "\n";
  if (rank >= 0) {
    s += "priority1 " + std::to_string(100 + rank) + "\n";
  } else {
    s += "priority1 255\n";
    s += "slaveOnly 1\n";
  }
  s += std::string("time_stamping ") + (c.hardware ? "hardware" : "software") + "\n";
  s += "logSyncInterval " + std::to_string(c.sync_interval_log) + "\n";
  // PTP over the same network as ccomm's frames: Ethernet for raw nodes, UDP for UDP ones.
  s += std::string("network_transport ") + (n.transport == TransportKind::kUdp ? "UDPv4" : "L2") + "\n";
  s += "uds_address " + c.socket + "\n";
  s += "[" + n.interface + "]\n";
  return s;
}

}  // namespace ccomm
