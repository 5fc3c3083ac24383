// SPDX-License-Identifier: Apache-2.0
// Windows unit, start-up only: room for a new segment (platform.h).
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <windows.h>

#include "common/platform.h"

namespace ccomm {
namespace platform {

// Mappings are backed by the paging file: its free part is the room.
uint64_t ShmRoom() {
  MEMORYSTATUSEX m;
  m.dwLength = sizeof m;
  return GlobalMemoryStatusEx(&m) ? static_cast<uint64_t>(m.ullAvailPageFile) : UINT64_MAX;
}

uint64_t CgroupMemoryRoom() { return UINT64_MAX; }  // no cgroups (a job object's limit is not read)

uint64_t AddressSpaceRoom() {
  MEMORYSTATUSEX m;
  m.dwLength = sizeof m;
  return GlobalMemoryStatusEx(&m) ? static_cast<uint64_t>(m.ullAvailVirtual) : UINT64_MAX;
}

}  // namespace platform
}  // namespace ccomm
