// SPDX-License-Identifier: Apache-2.0
// Files written whole and told apart (common/platform.h): the POSIX unit.
#include <cerrno>
#include <cstdio>
#include <sys/stat.h>
#include <unistd.h>

#include "common/platform.h"

namespace ccomm {
namespace platform {

int WriteFileAtomically(const char* path, const std::string& text) {
  const std::string tmp = std::string(path) + ".tmp";
  FILE* f = fopen(tmp.c_str(), "w");
  if (!f) return -errno;
  const bool wrote = fwrite(text.data(), 1, text.size(), f) == text.size();
  int err = wrote ? 0 : errno;
  if (fclose(f) != 0 && !err) err = errno;
  if (!err && rename(tmp.c_str(), path) != 0) err = errno;
  if (err) unlink(tmp.c_str());
  return -err;
}

FileIdentity IdentifyFile(const char* path) {
  FileIdentity id;
  struct stat st;
  if (stat(path, &st) != 0) return id;
  id.dev = static_cast<uint64_t>(st.st_dev);
  id.ino = static_cast<uint64_t>(st.st_ino);
  id.size = static_cast<uint64_t>(st.st_size);
  id.mtime_ns = static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  id.valid = true;
  return id;
}

}  // namespace platform
}  // namespace ccomm
