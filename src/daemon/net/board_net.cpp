// SPDX-License-Identifier: Apache-2.0
// ccommd --board-net's decision (board_net.h): pure, so every rule is unit-tested.
#include "daemon/net/board_net.h"

#include <string.h>

namespace ccomm {

namespace {

bool HasInterface(const std::vector<LocalInterface>& ifs, const std::string& name) {
  for (const LocalInterface& li : ifs)
    if (li.name == name) return true;
  return false;
}

// The interface to configure for node `n`: its interface=, else the one carrying its mac=.
std::string NodeInterface(const NodeConfig& n, const std::vector<LocalInterface>& ifs) {
  if (!n.interface.empty()) return n.interface;
  if (n.has_mac)
    for (const LocalInterface& li : ifs)
      if (li.has_mac && memcmp(li.mac, n.mac, 6) == 0) return li.name;
  return "";
}

// 1 with the plan for node `n` when its interface is there (or it names none), else 0/-1.
int PlanFor(const SystemConfig& cfg, int n, const std::string& how, const std::vector<LocalInterface>& ifs,
            bool last_try, BoardNetPlan* plan, std::string* error) {
  const NodeConfig& node = cfg.nodes[static_cast<size_t>(n)];
  const std::string ifname = NodeInterface(node, ifs);
  if (!ifname.empty() && !HasInterface(ifs, ifname)) {
    if (!last_try) return 0;
    std::string mine;
    for (const LocalInterface& li : ifs) mine += (mine.empty() ? "" : ", ") + li.name;
    *error = cfg.path + ":" + std::to_string(node.line) + ": this board is node '" + node.name + "' (" + how +
             ") but has no interface '" + ifname + "' (interfaces: " + (mine.empty() ? "none" : mine) + ")";
    return -1;
  }
  plan->node = n;
  plan->how = how;
  plan->interface = ifname;
  plan->address = node.ip.empty() ? "" : node.ip + "/" + std::to_string(kBoardNetPrefix);
  return 1;
}

}  // namespace

std::string KernelCmdlineNode(const std::string& cmdline) {
  static const char kKey[] = "ccomm.node=";
  std::string found;
  size_t i = 0;
  while (i < cmdline.size()) {
    while (i < cmdline.size() && (cmdline[i] == ' ' || cmdline[i] == '\t' || cmdline[i] == '\n')) ++i;
    size_t j = i;
    while (j < cmdline.size() && cmdline[j] != ' ' && cmdline[j] != '\t' && cmdline[j] != '\n') ++j;
    const std::string word = cmdline.substr(i, j - i);
    // The kernel's own rule: a later parameter overrides an earlier one.
    if (word.compare(0, sizeof kKey - 1, kKey) == 0) found = word.substr(sizeof kKey - 1);
    i = j;
  }
  return found;
}

int PlanBoardNet(const SystemConfig& cfg, const std::string& explicit_name, const char* explicit_from,
                 const std::string& hostname, const std::vector<LocalInterface>& interfaces, bool last_try,
                 BoardNetPlan* plan, std::string* error) {
  std::string how, why;
  if (!explicit_name.empty()) {
    const int n = IdentifyNode(cfg, explicit_name, explicit_from, "", interfaces, &how, &why);
    if (n < 0) {
      *error = why;
      return -1;
    }
    return PlanFor(cfg, n, how, interfaces, last_try, plan, error);
  }
  // The MAC (or an address already there) before the hostname: the hardware says which
  // board this is; the hostname may be the image's default or another board's.
  const int n = IdentifyNode(cfg, "", "", "", interfaces, &how, &why);
  if (n >= 0) return PlanFor(cfg, n, how, interfaces, last_try, plan, error);
  const int h = hostname.empty() ? -1 : cfg.FindNode(hostname);
  if (h >= 0) return PlanFor(cfg, h, "the hostname", interfaces, last_try, plan, error);
  if (!last_try) return 0;
  // IdentifyNode's message with the hostname in it: every way that was tried.
  IdentifyNode(cfg, "", "", hostname, interfaces, &how, &why);
  *error = why + "; or put ccomm.node=NAME on the kernel command line";
  return -1;
}

std::string BoardNetNetworkFile(const SystemConfig& cfg, const BoardNetPlan& plan) {
  const NodeConfig& node = cfg.nodes[static_cast<size_t>(plan.node)];
  std::string f;
  f += "# Written at boot by ccommd --board-net (ccomm-board-net.service) for node '" + node.name + "' of\n";
  f += "# " + cfg.path + ". Not to be edited: a file of the same name in /etc/systemd/network,\n";
  f += "# or one sorting before it, replaces it (ccommd(8), BOARD NETWORK).\n";
  f += "[Match]\nName=" + plan.interface + "\n\n";
  f += "[Link]\nRequiredForOnline=yes\n\n";
  f += "[Network]\n";
  if (!plan.address.empty()) f += "Address=" + plan.address + "\n";
  else f += "DHCP=ipv4\n";
  // Raw Ethernet needs the link, not an address: configure without carrier, and keep the
  // address through a cable cut (the peers come back to the same address).
  f += "ConfigureWithoutCarrier=yes\nIgnoreCarrierLoss=yes\nLinkLocalAddressing=no\nIPv6AcceptRA=no\n";
  return f;
}

}  // namespace ccomm
