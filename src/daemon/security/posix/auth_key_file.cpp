// SPDX-License-Identifier: Apache-2.0
// The pre-shared key file (auth.h, LoadKeyFile): opened once, checked for its type,
// mode and owner on the descriptor (no race with a swapped path), read raw or as hex.
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "daemon/security/auth.h"
#include "daemon/security/auth_crypto.h"

namespace ccomm {
namespace auth {
namespace {

int HexDigit(uint8_t c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

void Wipe(void* p, size_t n) { crypto::Wipe(p, n); }

}  // namespace

int LoadKeyFile(const std::string& path, uint8_t key[kKeyBytes], std::string* error) {
  int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    int e = errno;
    *error = "cannot open auth key file " + path + ": " + strerror(e);
    if (e == EACCES) *error += " (it must be readable by the user ccommd runs as)";
    return -e;
  }
  // Check the file we opened, not the name (no race with a swapped path).
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    *error = "auth key file " + path + " is not a regular file";
    return -EINVAL;
  }
  if (st.st_mode & (S_IRWXG | S_IRWXO)) {
    close(fd);
    char mode[8];
    snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    *error = "auth key file " + path + " has mode " + mode +
             ": a pre-shared key must not be accessible by group or others; refusing to start "
             "(fix: chmod 600 " + path + ")";
    return -EPERM;
  }
  if (st.st_uid != 0 && st.st_uid != geteuid()) {
    close(fd);
    *error = "auth key file " + path + " is owned by uid " + std::to_string(st.st_uid) +
             ", not by root or the user ccommd runs as; refusing to start";
    return -EPERM;
  }
  uint8_t buf[2 * kKeyBytes + 2];
  ssize_t n = read(fd, buf, sizeof buf);
  close(fd);
  int r = 0;
  if (n == static_cast<ssize_t>(kKeyBytes)) {
    memcpy(key, buf, kKeyBytes);
  } else if (n >= static_cast<ssize_t>(2 * kKeyBytes) && n <= static_cast<ssize_t>(2 * kKeyBytes + 1) &&
             (n == static_cast<ssize_t>(2 * kKeyBytes) || buf[2 * kKeyBytes] == '\n')) {
    for (size_t i = 0; i < kKeyBytes && r == 0; ++i) {
      int hi = HexDigit(buf[2 * i]), lo = HexDigit(buf[2 * i + 1]);
      if (hi < 0 || lo < 0) r = -EINVAL;
      else key[i] = static_cast<uint8_t>(hi << 4 | lo);
    }
  } else {
    r = -EINVAL;
  }
  Wipe(buf, sizeof buf);
  if (r != 0 || n < 0) {
    Wipe(key, kKeyBytes);
    *error = "auth key file " + path +
             " must hold exactly 32 random bytes or 64 hex digits (e.g. made with: "
             "head -c 32 /dev/urandom > FILE)";
    return -EINVAL;
  }
  return 0;
}

}  // namespace auth
}  // namespace ccomm
