// SPDX-License-Identifier: Apache-2.0
// The Windows unit of common/public/platform_app.h's exclusive lock (ccommd's node), and the
// group of an object (none).
#include <errno.h>
#include <stdio.h>

#include <windows.h>

#include "common/public/platform_app.h"

namespace ccomm {
namespace platform {

namespace {
HANDLE g_lock = nullptr;  // a process holds one node lock (ccommd)
}  // namespace

// A named mutex: Windows releases it (as "abandoned") when the owner dies; a suspended
// owner keeps it. One per process (ccommd's node), kept here rather than in the shm
// handle table: the caller gets handle 0.
int LockExclusive(const char* name, int /*gid: the session's default DACL*/, int* holder_pid) {
  *holder_pid = 0;
  char wname[300];
  const char* base = name[0] == '/' ? name + 1 : name;
  if (snprintf(wname, sizeof wname, "Local\\%s.mutex", base) >= static_cast<int>(sizeof wname)) return -ENAMETOOLONG;
  HANDLE m = CreateMutexA(nullptr, FALSE, wname);
  if (!m) return -EACCES;
  const DWORD w = WaitForSingleObject(m, 0);
  if (w == WAIT_OBJECT_0 || w == WAIT_ABANDONED) {
    if (g_lock) {  // a second lock in one process: not how ccommd uses it
      ReleaseMutex(m);
      CloseHandle(m);
      return -EINVAL;
    }
    g_lock = m;
    return 0;
  }
  CloseHandle(m);
  return -EBUSY;
}

void UnlockExclusive(int handle) {
  if (handle != 0 || !g_lock) return;
  ReleaseMutex(g_lock);
  CloseHandle(g_lock);
  g_lock = nullptr;
}

int NamedGroupId(const char* /*name*/) { return -1; }

}  // namespace platform
}  // namespace ccomm
