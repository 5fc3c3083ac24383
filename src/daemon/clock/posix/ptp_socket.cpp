// SPDX-License-Identifier: Apache-2.0
// The socket to ptp4l (ptp_state.h, Monitor): its management socket is a Unix datagram
// socket; ccommd binds an abstract name of its own for the answers.
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include "common/platform.h"
#include "daemon/clock/ptp_state.h"

namespace ccomm {
namespace ptp {

Monitor::~Monitor() {
  if (fd_ >= 0) close(fd_);
}

bool Monitor::OpenSocket() {
  if (fd_ >= 0) return true;
  fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) return false;
  // An abstract name of our own: ptp4l sends its answer to it, nothing on disk to clean.
  struct sockaddr_un self = {};
  self.sun_family = AF_UNIX;
  const int n = snprintf(self.sun_path + 1, sizeof self.sun_path - 1, "ccommd-ptp.%d.%p", static_cast<int>(platform::ProcessId()),
                         static_cast<void*>(this));
  const socklen_t slen = static_cast<socklen_t>(offsetof(struct sockaddr_un, sun_path) + 1 + n);
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&self), slen) != 0) {
    close(fd_);
    fd_ = -1;
    return false;
  }
  return true;
}

void Monitor::Poll(uint64_t now_ns) {
  (void)now_ns;
  if (path_.empty() || !OpenSocket()) return;
  struct sockaddr_un to = {};
  to.sun_family = AF_UNIX;
  if (path_.size() >= sizeof to.sun_path) return;
  memcpy(to.sun_path, path_.data(), path_.size());
  uint8_t msg[64];
  awaited_ = 0;
  for (uint16_t id : {kIdTimeStatusNp, kIdPortDataSet}) {
    const size_t len = BuildGet(msg, sizeof msg, id, ++sequence_, domain_);
    // ENOENT / ECONNREFUSED: no ptp4l; the silence decides (Evaluate).
    if (sendto(fd_, msg, len, MSG_DONTWAIT | MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&to), sizeof to) >= 0)
      ++awaited_;
  }
}

void Monitor::Drain(uint64_t now_ns) {
  if (fd_ < 0 || awaited_ == 0) return;
  uint8_t buf[512];
  for (int i = 0; i < 16; ++i) {  // bounded: two answers a poll, and stray ones
    const ssize_t n = recv(fd_, buf, sizeof buf, MSG_DONTWAIT);
    if (n <= 0) return;
    Reply r;
    if (!ParseReply(buf, static_cast<size_t>(n), &r)) continue;
    Answer(r, now_ns);
    if (awaited_ > 0) --awaited_;
  }
}

}  // namespace ptp
}  // namespace ccomm
