// SPDX-License-Identifier: Apache-2.0
// This PC's interfaces for node identification (node_identity.h): GetAdaptersAddresses.
// An interface's name is its friendly name ("Ethernet 2"), as `netsh` shows it.
#include <stdlib.h>
#include <string.h>

// clang-format off
#include <winsock2.h>  // before windows.h
#include <ws2tcpip.h>
#include <windows.h>
#include <iphlpapi.h>
// clang-format on
#undef interface  // objbase.h's macro; NodeConfig has a member of that name

#include "daemon/net/node_identity.h"

namespace ccomm {

std::vector<LocalInterface> LocalInterfaces() {
  std::vector<LocalInterface> out;
  ULONG size = 16 * 1024;
  std::vector<unsigned char> buf;
  ULONG r = ERROR_BUFFER_OVERFLOW;
  for (int tries = 0; tries < 3 && r == ERROR_BUFFER_OVERFLOW; ++tries) {  // the list may grow between calls
    buf.resize(size);
    r = GetAdaptersAddresses(AF_UNSPEC, GAA_FLAG_SKIP_ANYCAST | GAA_FLAG_SKIP_MULTICAST | GAA_FLAG_SKIP_DNS_SERVER,
                             nullptr, reinterpret_cast<IP_ADAPTER_ADDRESSES*>(buf.data()), &size);
  }
  if (r != NO_ERROR) return out;
  for (auto* a = reinterpret_cast<IP_ADAPTER_ADDRESSES*>(buf.data()); a; a = a->Next) {
    if (a->IfType == IF_TYPE_SOFTWARE_LOOPBACK) continue;
    LocalInterface li;
    char name[256] = "";
    WideCharToMultiByte(CP_UTF8, 0, a->FriendlyName, -1, name, sizeof name, nullptr, nullptr);
    li.name = name;
    if (a->PhysicalAddressLength == 6) {
      li.has_mac = true;
      memcpy(li.mac, a->PhysicalAddress, 6);
    }
    for (auto* u = a->FirstUnicastAddress; u; u = u->Next) {
      if (u->Address.lpSockaddr->sa_family != AF_INET) continue;
      char text[INET_ADDRSTRLEN];
      const auto* in = reinterpret_cast<const struct sockaddr_in*>(u->Address.lpSockaddr);
      if (inet_ntop(AF_INET, &in->sin_addr, text, sizeof text)) li.ipv4.push_back(text);
    }
    out.push_back(li);
  }
  return out;
}

}  // namespace ccomm
