// SPDX-License-Identifier: Apache-2.0
// ccommd --board-net: one image and one signals.xml for every board. At boot, before
// ccommd, it finds which node this board is, sets the hostname to the node's name,
// brings the node's interface up and gives it the node's address (ip=, /24) or DHCP
// (no ip=: a systemd-networkd .network file). The decision is a pure function
// (unit-tested in board_net_test.cpp); applying it is Linux code (board_net_linux.cpp).
#pragma once

#include <string>
#include <vector>

#include "config/config.h"
#include "daemon/net/node_identity.h"

namespace ccomm {

/// The prefix length of a static address from ip=: signals.xml has no field for it, and
/// the boards of one robot share one switch and one /24 (docs/config.md).
constexpr int kBoardNetPrefix = 24;

struct BoardNetPlan {
  int node = -1;
  std::string how;        // how the node was found, for the log
  std::string interface;  // to bring up and address; empty: the node names none (hostname only)
  std::string address;    // "A.B.C.D/24" from ip=; empty: DHCP (when interface is set)
};

/// The NAME of the last ccomm.node=NAME in a kernel command line (/proc/cmdline), or "".
std::string KernelCmdlineNode(const std::string& cmdline);

/// Which node this board is and what its interface gets. The node: `explicit_name` (from
/// `explicit_from`: --node, $CCOMM_NODE or ccomm.node=) if given, else the one node whose
/// mac= (then ip=) is on `interfaces`, else the node named by `hostname`. Returns 1 with
/// `plan` set; 0 when that is not known yet (the node's interface is missing, or nothing
/// matches: the network drivers may still be probing) and `last_try` is false; -1 with
/// `error` saying why and what was tried.
int PlanBoardNet(const SystemConfig& cfg, const std::string& explicit_name, const char* explicit_from,
                 const std::string& hostname, const std::vector<LocalInterface>& interfaces, bool last_try,
                 BoardNetPlan* plan, std::string* error);

/// The systemd-networkd .network file for `plan` (interface set): Address= or DHCP=ipv4,
/// kept through a carrier loss (a cable cut must not take the address away).
std::string BoardNetNetworkFile(const SystemConfig& cfg, const BoardNetPlan& plan);

/// Applies `plan`: hostname, link up, the static address, and the .network file in
/// `network_dir` (none if empty).
/// Returns 0, or -1 with `error`; `done` lists what was done, for the log.
int ApplyBoardNet(const SystemConfig& cfg, const BoardNetPlan& plan, const std::string& network_dir,
                  std::vector<std::string>* done, std::string* error);

}  // namespace ccomm
