// SPDX-License-Identifier: Apache-2.0
// Files written whole and told apart (common/platform.h): the Windows unit. The identity
// is the volume serial and file index (what st_dev and st_ino stand for on NTFS) with the
// last write time in 100 ns steps.
#include <windows.h>

#include <cerrno>
#include <cstdio>

#include "common/platform.h"
#include "common/platform/windows/errno_of.h"

namespace ccomm {
namespace platform {

int WriteFileAtomically(const char* path, const std::string& text) {
  const std::string tmp = std::string(path) + ".tmp";
  HANDLE f = CreateFileA(tmp.c_str(), GENERIC_WRITE, 0, nullptr, CREATE_ALWAYS, FILE_ATTRIBUTE_NORMAL, nullptr);
  if (f == INVALID_HANDLE_VALUE) return -ErrnoOf(GetLastError());
  DWORD err = 0;
  size_t put = 0;
  while (!err && put < text.size()) {
    DWORD n = 0;
    if (!WriteFile(f, text.data() + put, static_cast<DWORD>(text.size() - put), &n, nullptr)) err = GetLastError();
    put += n;
  }
  if (!CloseHandle(f) && !err) err = GetLastError();
  if (!err && !MoveFileExA(tmp.c_str(), path, MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH)) err = GetLastError();
  if (err) DeleteFileA(tmp.c_str());
  return err ? -ErrnoOf(err) : 0;
}

FileIdentity IdentifyFile(const char* path) {
  FileIdentity id;
  HANDLE f = CreateFileA(path, 0, FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE, nullptr, OPEN_EXISTING,
                         FILE_FLAG_BACKUP_SEMANTICS, nullptr);
  if (f == INVALID_HANDLE_VALUE) return id;
  BY_HANDLE_FILE_INFORMATION info;
  if (GetFileInformationByHandle(f, &info)) {
    id.dev = info.dwVolumeSerialNumber;
    id.ino = (static_cast<uint64_t>(info.nFileIndexHigh) << 32) | info.nFileIndexLow;
    id.size = (static_cast<uint64_t>(info.nFileSizeHigh) << 32) | info.nFileSizeLow;
    const uint64_t t = (static_cast<uint64_t>(info.ftLastWriteTime.dwHighDateTime) << 32) |
                       info.ftLastWriteTime.dwLowDateTime;
    id.mtime_ns = static_cast<int64_t>(t) * 100;
    id.valid = true;
  }
  CloseHandle(f);
  return id;
}

}  // namespace platform
}  // namespace ccomm
