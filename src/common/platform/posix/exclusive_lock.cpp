// SPDX-License-Identifier: Apache-2.0
// The POSIX unit of common/public/platform_app.h's exclusive lock (ccommd's node, ccomm-ros2's
// node and DDS domain), and the group its object gets.
#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/public/platform_app.h"

namespace ccomm {
namespace platform {

// A record lock (fcntl) on a small shm object: the kernel drops it when the process
// exits or is killed, and a stopped process keeps it.
int LockExclusive(const char* name, int gid, int* holder_pid) {
  *holder_pid = 0;
  int fd = shm_open(name, O_RDWR | O_CREAT | O_CLOEXEC, 0660);
  if (fd < 0) return -errno;
  // The first holder creates it: umask must not narrow it, and the group shares it.
  struct stat st;
  if (fstat(fd, &st) == 0 && st.st_uid == geteuid()) {
    if (fchmod(fd, 0660) != 0) { /* best effort: the lock works without */ }
    if (gid >= 0 && fchown(fd, static_cast<uid_t>(-1), static_cast<gid_t>(gid)) != 0) { /* idem */ }
  }
  struct flock lk;
  memset(&lk, 0, sizeof lk);
  lk.l_type = F_WRLCK;
  lk.l_whence = SEEK_SET;
  if (fcntl(fd, F_SETLK, &lk) == 0) return fd;
  const int e = errno;
  if (e == EAGAIN || e == EACCES) {
    memset(&lk, 0, sizeof lk);
    lk.l_type = F_WRLCK;
    lk.l_whence = SEEK_SET;
    if (fcntl(fd, F_GETLK, &lk) == 0 && lk.l_type != F_UNLCK) *holder_pid = lk.l_pid;
    close(fd);
    return -EBUSY;
  }
  close(fd);
  return -e;
}

void UnlockExclusive(int handle) {
  if (handle >= 0) close(handle);
}

int NamedGroupId(const char* name) {
  const struct group* g = getgrnam(name);
  return g ? static_cast<int>(g->gr_gid) : -1;
}

}  // namespace platform
}  // namespace ccomm
