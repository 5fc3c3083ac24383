// SPDX-License-Identifier: Apache-2.0
// Which node of signals.xml this board is, so one image and one file serve every board:
// --node, else $CCOMM_NODE, else the hostname if it names a node, else the node whose
// mac= (or, failing that, ip=) is on one of this board's interfaces.
#pragma once

#include <string>
#include <vector>

#include "config/config.h"

namespace ccomm {

/// A local interface's addresses (net/posix/node_interfaces.cpp, net/windows/node_interfaces.cpp).
struct LocalInterface {
  std::string name;
  bool has_mac = false;
  uint8_t mac[6] = {};
  std::vector<std::string> ipv4;  // dotted quads
};

/// This board's interfaces (loopback excluded).
std::vector<LocalInterface> LocalInterfaces();

/// The node `explicit_name` (from --node or $CCOMM_NODE; may be empty) or, without one,
/// the hostname's node or the one node matching `interfaces` (MAC first, then IP).
/// Returns its index, or -1 with `error` saying why and what was tried; `how` says how
/// it was found (for the log).
int IdentifyNode(const SystemConfig& cfg, const std::string& explicit_name, const char* explicit_from,
                 const std::string& hostname, const std::vector<LocalInterface>& interfaces, std::string* how,
                 std::string* error);

}  // namespace ccomm
