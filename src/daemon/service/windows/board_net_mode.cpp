// SPDX-License-Identifier: Apache-2.0
// ccommd --board-net on Windows (board_net_mode.h): a PC's network is its owner's.
#include "daemon/service/board_net_mode.h"

#include "common/platform.h"

namespace ccomm {

int RunBoardNet(const SystemConfig& /*cfg*/, const std::string& /*explicit_node*/, const char* /*explicit_from*/,
                bool /*dry_run*/, const std::string& /*network_dir*/, bool /*network_dir_given*/) {
  Log(LogLevel::kError, "ccommd: --board-net configures a Linux board's network; not on Windows");
  return 2;
}

}  // namespace ccomm
