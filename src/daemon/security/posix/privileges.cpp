// SPDX-License-Identifier: Apache-2.0
// Capability dropping with the raw capget/capset/prctl interface (no libcap needed).
#include "daemon/security/privileges.h"

#include <errno.h>
#include <linux/capability.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace ccomm {
namespace {

// Raises the soft (and if needed hard) limit to at least `want`; true if it holds.
bool EnsureLimit(int resource, rlim_t want) {
  struct rlimit rl;
  if (getrlimit(resource, &rl) != 0) return false;
  if (rl.rlim_cur == RLIM_INFINITY || (want != RLIM_INFINITY && rl.rlim_cur >= want)) return true;
  if (rl.rlim_max != RLIM_INFINITY && (want == RLIM_INFINITY || rl.rlim_max < want)) rl.rlim_max = want;
  rl.rlim_cur = want;
  return setrlimit(resource, &rl) == 0;  // raising the hard limit needs CAP_SYS_RESOURCE
}

bool Has(const __user_cap_data_struct* d, int cap) { return d[cap / 32].permitted & (1u << (cap % 32)); }

}  // namespace

int DropPrivileges(const RealtimeConfig& rt, bool realtime, std::string* summary) {
  struct __user_cap_header_struct hdr = {_LINUX_CAPABILITY_VERSION_3, 0};
  struct __user_cap_data_struct cur[2] = {};
  if (syscall(SYS_capget, &hdr, cur) != 0) return -errno;

  // What the I/O threads still do with privileges, moved to resource limits if possible.
  uint64_t keep = 0;
  if (realtime && rt.priority > 0 && !EnsureLimit(RLIMIT_RTPRIO, static_cast<rlim_t>(rt.priority)) &&
      Has(cur, CAP_SYS_NICE))
    keep |= uint64_t{1} << CAP_SYS_NICE;
  if (realtime && rt.mlockall && !EnsureLimit(RLIMIT_MEMLOCK, RLIM_INFINITY) && Has(cur, CAP_IPC_LOCK))
    keep |= uint64_t{1} << CAP_IPC_LOCK;

  // Bounding set first: dropping from it needs CAP_SETPCAP, which goes with the rest.
  int bounded = 0;
  if (Has(cur, CAP_SETPCAP)) {
    for (int c = 0; c <= CAP_LAST_CAP; ++c)
      if (!(keep & (uint64_t{1} << c)) && prctl(PR_CAPBSET_DROP, c, 0, 0, 0) == 0) ++bounded;
  }
  prctl(PR_CAP_AMBIENT, PR_CAP_AMBIENT_CLEAR_ALL, 0, 0, 0);  // EINVAL before Linux 4.3: none then
  struct __user_cap_data_struct next[2] = {};
  for (int i = 0; i < 2; ++i) {
    uint32_t k = static_cast<uint32_t>(keep >> (32 * i));
    next[i].permitted = cur[i].permitted & k;
    next[i].effective = cur[i].permitted & k;
  }
  if (syscall(SYS_capset, &hdr, next) != 0) return -errno;
  if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) return -errno;

  *summary = "capabilities dropped";
  if (keep) {
    *summary += " except";
    if (keep & (uint64_t{1} << CAP_SYS_NICE)) *summary += " CAP_SYS_NICE (RLIMIT_RTPRIO too low: LimitRTPRIO=)";
    if (keep & (uint64_t{1} << CAP_IPC_LOCK)) *summary += " CAP_IPC_LOCK (RLIMIT_MEMLOCK limited: LimitMEMLOCK=)";
  }
  if (bounded) *summary += ", bounding set cleared";
  *summary += ", no_new_privs set";
  return 0;
}

}  // namespace ccomm
