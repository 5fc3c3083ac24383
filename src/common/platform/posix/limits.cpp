// SPDX-License-Identifier: Apache-2.0
// POSIX unit, start-up only: room for a new segment (platform.h).
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <string>

#include "common/platform.h"

namespace ccomm {
namespace platform {

uint64_t ShmRoom() {
  struct statvfs vfs;
  if (statvfs("/dev/shm", &vfs) != 0) return UINT64_MAX;
  return uint64_t{vfs.f_bavail} * vfs.f_frsize;
}

uint64_t CgroupMemoryRoom() {
  uint64_t room = UINT64_MAX;
  FILE* f = fopen("/proc/self/cgroup", "r");
  if (!f) return room;
  char line[512], path[512] = "";
  while (fgets(line, sizeof line, f))
    if (strncmp(line, "0::", 3) == 0) snprintf(path, sizeof path, "%s", line + 3);
  fclose(f);
  path[strcspn(path, "\n")] = '\0';
  std::string dir = path;
  for (;;) {
    unsigned long long max = 0, current = 0;
    const std::string base = "/sys/fs/cgroup" + dir;
    FILE* m = fopen((base + "/memory.max").c_str(), "r");
    FILE* c = fopen((base + "/memory.current").c_str(), "r");
    if (m && c && fscanf(m, "%llu", &max) == 1 && fscanf(c, "%llu", &current) == 1)
      room = std::min<uint64_t>(room, max > current ? max - current : 0);
    if (m) fclose(m);
    if (c) fclose(c);
    const size_t slash = dir.rfind('/');
    if (dir.empty() || slash == std::string::npos) break;
    dir.resize(slash);
  }
  return room;
}

uint64_t AddressSpaceRoom() {
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return UINT64_MAX;
  unsigned long long pages = 0;
  if (FILE* f = fopen("/proc/self/statm", "r")) {
    if (fscanf(f, "%llu", &pages) != 1) pages = 0;
    fclose(f);
  }
  const uint64_t used = pages * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
  return rl.rlim_cur > used ? rl.rlim_cur - used : 0;
}

}  // namespace platform
}  // namespace ccomm
