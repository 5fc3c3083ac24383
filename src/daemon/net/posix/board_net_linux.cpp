// SPDX-License-Identifier: Apache-2.0
// ccommd --board-net's actions (board_net.h), Linux: sethostname(2), the interface
// ioctls (no ip(8) needed on the image), and the .network file for systemd-networkd.
#include <arpa/inet.h>
#include <errno.h>
#include <net/if.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/platform.h"
#include "daemon/net/board_net.h"

namespace ccomm {

namespace {

std::string Errno(const std::string& what) { return what + ": " + strerror(errno); }

int SetAddress(int fd, const char* ifname, unsigned long request, uint32_t network_order, std::string* error,
               const char* what) {
  struct ifreq ifr;
  memset(&ifr, 0, sizeof ifr);
  snprintf(ifr.ifr_name, sizeof ifr.ifr_name, "%s", ifname);
  struct sockaddr_in sin;
  memset(&sin, 0, sizeof sin);
  sin.sin_family = AF_INET;
  sin.sin_addr.s_addr = network_order;
  memcpy(&ifr.ifr_addr, &sin, sizeof sin);
  if (ioctl(fd, request, &ifr) != 0) {
    *error = Errno(std::string("cannot set the ") + what + " of " + ifname);
    return -1;
  }
  return 0;
}

int MakeDirs(const std::string& dir) {
  for (size_t i = 1; i <= dir.size(); ++i) {
    if (i < dir.size() && dir[i] != '/') continue;
    if (mkdir(dir.substr(0, i).c_str(), 0755) != 0 && errno != EEXIST) return -1;
  }
  return 0;
}

}  // namespace

int ApplyBoardNet(const SystemConfig& cfg, const BoardNetPlan& plan, const std::string& network_dir,
                  std::vector<std::string>* done, std::string* error) {
  const NodeConfig& node = cfg.nodes[static_cast<size_t>(plan.node)];
  char host[256] = "";
  if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  if (node.name != host) {
    if (sethostname(node.name.data(), node.name.size()) != 0) {
      *error = Errno("cannot set the hostname to '" + node.name + "'");
      return -1;
    }
    done->push_back("hostname " + node.name + (host[0] ? " (was " + std::string(host) + ")" : ""));
  }
  if (plan.interface.empty()) {
    done->push_back("no interface to configure: node '" + node.name + "' names no interface= or mac=");
    return 0;
  }
  const char* ifname = plan.interface.c_str();
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    *error = Errno("socket");
    return -1;
  }
  struct ifreq ifr;
  memset(&ifr, 0, sizeof ifr);
  snprintf(ifr.ifr_name, sizeof ifr.ifr_name, "%s", ifname);
  if (ioctl(fd, SIOCGIFFLAGS, &ifr) != 0) {
    *error = Errno(std::string("cannot read the flags of ") + ifname);
    close(fd);
    return -1;
  }
  if (!(ifr.ifr_flags & IFF_UP)) {
    ifr.ifr_flags = static_cast<short>(ifr.ifr_flags | IFF_UP);
    if (ioctl(fd, SIOCSIFFLAGS, &ifr) != 0) {
      *error = Errno(std::string("cannot bring ") + ifname + " up");
      close(fd);
      return -1;
    }
    done->push_back(plan.interface + " up");
  }
  if (!plan.address.empty()) {
    uint32_t addr = 0;
    if (inet_pton(AF_INET, node.ip.c_str(), &addr) != 1) {
      *error = cfg.path + ":" + std::to_string(node.line) + ": ip=\"" + node.ip + "\" is not an IPv4 address";
      close(fd);
      return -1;
    }
    const uint32_t mask = htonl(~0u << (32 - kBoardNetPrefix));
    if (SetAddress(fd, ifname, SIOCSIFADDR, addr, error, "address") != 0 ||
        SetAddress(fd, ifname, SIOCSIFNETMASK, mask, error, "netmask") != 0) {
      close(fd);
      return -1;
    }
    done->push_back(plan.interface + " " + plan.address);
  }
  close(fd);
  // networkd then manages the link with the same settings (so network-online.target means
  // this link, and a DHCP lease is renewed).
  if (!network_dir.empty()) {
    const std::string path = network_dir + "/10-ccomm-board.network";
    if (MakeDirs(network_dir) != 0) {
      *error = Errno("cannot create " + network_dir);
      return -1;
    }
    // Whole or not at all: a half file would configure nothing.
    const int w = platform::WriteFileAtomically(path.c_str(), BoardNetNetworkFile(cfg, plan));
    if (w != 0) {
      *error = "cannot write " + path + ": " + strerror(-w);
      return -1;
    }
    done->push_back(path + (plan.address.empty() ? " (DHCP, by systemd-networkd)" : ""));
  }
  return 0;
}

}  // namespace ccomm
