// SPDX-License-Identifier: Apache-2.0
// This board's interfaces for node identification (node_identity.h): getifaddrs.
#include <arpa/inet.h>
#include <ifaddrs.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <string.h>

#include "daemon/net/node_identity.h"

namespace ccomm {

std::vector<LocalInterface> LocalInterfaces() {
  std::vector<LocalInterface> out;
  struct ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return out;
  for (struct ifaddrs* a = list; a; a = a->ifa_next) {
    if (!a->ifa_addr || (a->ifa_flags & IFF_LOOPBACK)) continue;
    LocalInterface* li = nullptr;
    for (auto& e : out)
      if (e.name == a->ifa_name) li = &e;
    if (!li) {
      out.push_back(LocalInterface());
      li = &out.back();
      li->name = a->ifa_name;
    }
    if (a->ifa_addr->sa_family == AF_PACKET) {
      const auto* ll = reinterpret_cast<const struct sockaddr_ll*>(a->ifa_addr);
      if (ll->sll_halen == 6) {
        li->has_mac = true;
        memcpy(li->mac, ll->sll_addr, 6);
      }
    } else if (a->ifa_addr->sa_family == AF_INET) {
      char buf[INET_ADDRSTRLEN];
      const auto* in = reinterpret_cast<const struct sockaddr_in*>(a->ifa_addr);
      if (inet_ntop(AF_INET, &in->sin_addr, buf, sizeof buf)) li->ipv4.push_back(buf);
    }
  }
  freeifaddrs(list);
  return out;
}

}  // namespace ccomm
