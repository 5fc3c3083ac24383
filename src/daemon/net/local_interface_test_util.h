// SPDX-License-Identifier: Apache-2.0
// Tests only: a LocalInterface as a test describes one (node_identity_test, board_net_test).
#pragma once

#include <string.h>

#include <string>
#include <utility>
#include <vector>

#include "daemon/net/node_identity.h"

namespace ccomm {

/// Interface `name` with `ips` (dotted quads) and, when given, the MAC `mac` (6 bytes).
inline LocalInterface If(const char* name, std::vector<std::string> ips, const uint8_t* mac = nullptr) {
  LocalInterface li;
  li.name = name;
  li.ipv4 = std::move(ips);
  if (mac) {
    li.has_mac = true;
    memcpy(li.mac, mac, 6);
  }
  return li;
}

}  // namespace ccomm
