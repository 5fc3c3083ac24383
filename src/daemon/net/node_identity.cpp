// SPDX-License-Identifier: Apache-2.0
// Node identification (node_identity.h): the decision, a pure function, unit-tested.
// The interface listing is platform code: net/posix/node_interfaces.cpp (getifaddrs),
// net/windows/node_interfaces.cpp (GetAdaptersAddresses).
#include "daemon/net/node_identity.h"

#include <stdio.h>
#include <string.h>

namespace ccomm {

namespace {

std::string MacText(const uint8_t m[6]) {
  char b[18];
  snprintf(b, sizeof b, "%02x:%02x:%02x:%02x:%02x:%02x", m[0], m[1], m[2], m[3], m[4], m[5]);
  return b;
}

std::string NodeNames(const SystemConfig& cfg) {
  std::string names;
  for (const auto& n : cfg.nodes) names += (names.empty() ? "" : ", ") + n.name;
  return names;
}

// Nodes matching the interfaces by `key`: "mac" or "ip".
std::vector<int> Matches(const SystemConfig& cfg, const std::vector<LocalInterface>& ifs, bool by_mac,
                         std::string* found_on) {
  std::vector<int> nodes;
  for (size_t i = 0; i < cfg.nodes.size(); ++i) {
    const NodeConfig& n = cfg.nodes[i];
    for (const LocalInterface& li : ifs) {
      bool hit = by_mac ? (n.has_mac && li.has_mac && memcmp(n.mac, li.mac, 6) == 0)
                        : (!n.ip.empty() && [&] {
                            for (const auto& a : li.ipv4)
                              if (a == n.ip) return true;
                            return false;
                          }());
      if (hit) {
        nodes.push_back(static_cast<int>(i));
        *found_on += (found_on->empty() ? "" : ", ") + n.name + " by " + (by_mac ? "mac " + MacText(n.mac) : "ip " + n.ip) +
                     " on " + li.name;
        break;
      }
    }
  }
  return nodes;
}

}  // namespace

int IdentifyNode(const SystemConfig& cfg, const std::string& explicit_name, const char* explicit_from,
                 const std::string& hostname, const std::vector<LocalInterface>& interfaces, std::string* how,
                 std::string* error) {
  if (!explicit_name.empty()) {
    int n = cfg.FindNode(explicit_name);
    if (n < 0)
      *error = cfg.path + " has no node '" + explicit_name + "' (" + explicit_from + "; nodes: " + NodeNames(cfg) + ")";
    else
      *how = explicit_from;
    return n;
  }
  int n = hostname.empty() ? -1 : cfg.FindNode(hostname);
  if (n >= 0) {
    *how = "the hostname";
    return n;
  }
  for (bool by_mac : {true, false}) {
    std::string found;
    std::vector<int> hits = Matches(cfg, interfaces, by_mac, &found);
    if (hits.size() == 1) {
      *how = found;
      return hits[0];
    }
    if (hits.size() > 1) {
      *error = "this board matches several nodes of " + cfg.path + " (" + found +
               "): pass --node NAME or set CCOMM_NODE";
      return -1;
    }
  }
  std::string mine;
  for (const LocalInterface& li : interfaces) {
    mine += (mine.empty() ? "" : "; ") + li.name + (li.has_mac ? " " + MacText(li.mac) : "");
    for (const auto& a : li.ipv4) mine += " " + a;
  }
  *error = "no node of " + cfg.path + " is this board: the hostname '" + hostname +
           "' names none, and no node's mac= or ip= is on its interfaces (" + (mine.empty() ? "none" : mine) +
           "; nodes: " + NodeNames(cfg) + "): pass --node NAME, set CCOMM_NODE, set the hostname, or give "
           "the node this board's mac= or ip=";
  return -1;
}

}  // namespace ccomm
