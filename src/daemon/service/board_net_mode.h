// SPDX-License-Identifier: Apache-2.0
// ccommd --board-net: give this board the hostname and the address its node has in
// signals.xml (the decision: net/board_net.h). Linux only (posix/board_net_mode.cpp);
// on Windows it says so (windows/board_net_mode.cpp).
#pragma once

#include <string>

#include "config/config.h"

namespace ccomm {

/// Waits up to 60 s (CCOMM_BOARD_NET_WAIT_S) for the node's interface, then configures
/// it; with `dry_run` prints the .network file instead. The node is `explicit_node`
/// (named by `explicit_from`) or, if empty, ccomm.node= on the kernel command line, else
/// identified. Returns the exit status: 0 done, 1 no node or failed, 2 not on this platform.
int RunBoardNet(const SystemConfig& cfg, const std::string& explicit_node, const char* explicit_from, bool dry_run,
                const std::string& network_dir, bool network_dir_given);

}  // namespace ccomm
