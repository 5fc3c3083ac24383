// SPDX-License-Identifier: Apache-2.0
// ccommd --board-net on Linux (board_net_mode.h): the board's network from signals.xml.
#include "daemon/service/board_net_mode.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <string>
#include <vector>

#include "common/platform.h"
#include "config/config.h"
#include "daemon/net/board_net.h"
#include "daemon/net/node_identity.h"

namespace ccomm {
namespace {

// How long --board-net waits for the node's interface: the network driver may still be
// probing at boot (on a slow first boot, beside the SSH host keys being made, an emulated
// board's eth0 came more than 10 s after ccommd started). CCOMM_BOARD_NET_WAIT_S (0..600)
// changes it (the tests' no-node case).
constexpr uint64_t kBoardNetWaitS = 60;

uint64_t BoardNetWaitS() {
  const char* v = getenv("CCOMM_BOARD_NET_WAIT_S");
  char* end = nullptr;
  const unsigned long n = v && *v ? strtoul(v, &end, 10) : 0;
  if (!v || !*v || *end || n > 600) {
    if (v && *v)
      Log(LogLevel::kWarning, "ccommd: CCOMM_BOARD_NET_WAIT_S='%s' is not 0..600; waiting %u s", v,
          static_cast<unsigned>(kBoardNetWaitS));
    return kBoardNetWaitS;
  }
  return n;
}

}  // namespace

int RunBoardNet(const SystemConfig& cfg, const std::string& explicit_node, const char* explicit_from,
                bool dry_run, const std::string& network_dir, bool network_dir_given) {
  std::string name = explicit_node, from = explicit_from;
  if (name.empty()) {
    // /proc/cmdline: one line, size 0 to stat (so not ReadRegularFile).
    char line[4096] = "";
    if (FILE* f = fopen("/proc/cmdline", "r")) {
      if (!fgets(line, sizeof line, f)) line[0] = '\0';
      fclose(f);
    }
    name = KernelCmdlineNode(line);
    from = "ccomm.node= on the kernel command line";
  }
  BoardNetPlan plan;
  std::string error;
  const uint64_t wait_s = BoardNetWaitS();
  const uint64_t t0 = platform::MonotonicNs(), limit_ns = wait_s * 1000 * 1000 * 1000;
  int r = 0;
  for (bool said = false;;) {
    char host[256] = "";
    if (!platform::HostName(host, sizeof host)) host[0] = '\0';
    const bool last = platform::MonotonicNs() - t0 >= limit_ns;
    r = PlanBoardNet(cfg, name, from.c_str(), host, LocalInterfaces(), last, &plan, &error);
    if (r != 0) break;
    if (!said)
      Log(LogLevel::kNotice, "board-net: this board's node or its interface is not there yet; waiting up to %u s",
          static_cast<unsigned>(wait_s));
    said = true;
    platform::SleepNs(100ull * 1000 * 1000);
  }
  if (r < 0) {
    Log(LogLevel::kError, "ccommd --board-net: %s", error.c_str());
    return 1;
  }
  const NodeConfig& node = cfg.nodes[static_cast<size_t>(plan.node)];
  Log(LogLevel::kNotice, "board-net: this board is node '%s' (%s): hostname %s, interface %s, %s", node.name.c_str(),
      plan.how.c_str(), node.name.c_str(), plan.interface.empty() ? "none" : plan.interface.c_str(),
      plan.interface.empty() ? "no address" : plan.address.empty() ? "DHCP" : plan.address.c_str());
  if (dry_run) {
    if (!plan.interface.empty()) fputs(BoardNetNetworkFile(cfg, plan).c_str(), stdout);
    return 0;
  }
  // The .network file where systemd runs (networkd then manages the link with the same
  // settings) or where DHCP needs it; without systemd a static address is enough.
  std::string dir = network_dir;
  struct stat st;
  if (!network_dir_given && !plan.address.empty() && stat("/run/systemd/system", &st) != 0) dir.clear();
  std::vector<std::string> done;
  if (ApplyBoardNet(cfg, plan, dir, &done, &error) != 0) {
    Log(LogLevel::kError, "ccommd --board-net: %s", error.c_str());
    return 1;
  }
  for (const std::string& d : done) Log(LogLevel::kInfo, "board-net: %s", d.c_str());
  return 0;
}

}  // namespace ccomm
