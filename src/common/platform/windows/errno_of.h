// SPDX-License-Identifier: Apache-2.0
// The errno value of a Windows error code, for the Windows units that return -errno as
// their POSIX twins do (platform.h). Private to src/common/platform/windows/.
#pragma once

#include <errno.h>

#include <windows.h>

namespace ccomm {
namespace platform {

inline int ErrnoOf(DWORD e) {
  switch (e) {
    case ERROR_FILE_NOT_FOUND:
    case ERROR_PATH_NOT_FOUND: return ENOENT;
    case ERROR_ALREADY_EXISTS: return EEXIST;
    case ERROR_ACCESS_DENIED:
    case ERROR_PRIVILEGE_NOT_HELD: return EACCES;
    case ERROR_NOT_ENOUGH_MEMORY:
    case ERROR_OUTOFMEMORY:
    case ERROR_COMMITMENT_LIMIT: return ENOMEM;
    case ERROR_INVALID_HANDLE: return EBADF;
    default: return EIO;
  }
}

}  // namespace platform
}  // namespace ccomm
