// SPDX-License-Identifier: Apache-2.0
// Tests only: lets doorbell_xddp.cpp build and run on plain Linux, so its relay protocol
// (rings, waits and their answers, shutdown) runs under the client tests
// (client_xddp_emulated_test). Stands in for Xenomai's <rtdm/ipc.h> and the POSIX
// skin's __RT()/__STD() call wrappers: an "XDDP socket" is one end of an AF_UNIX
// SOCK_SEQPACKET pair (datagrams, like XDDP), its port is that fd, and "/dev/rtpN" hands
// over the other end. What it cannot show: Cobalt's scheduling (mode switches); that needs a
// Cobalt kernel (docs/design.md, "Xenomai").
#pragma once

#include <fcntl.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/socket.h>
#include <unistd.h>

#define AF_RTIPC 111
#define IPCPROTO_XDDP 1
#define SOL_XDDP 311
#define XDDP_POOLSZ 2

struct sockaddr_ipc {
  sa_family_t sipc_family;
  int32_t sipc_port;
};

#define __RT(call) xddp_emulated_rt_##call
#define __STD(call) xddp_emulated_std_##call

// The Linux end of each emulated socket, by the socket's fd, until "/dev/rtpN" takes it.
static int xddp_emulated_linux_end[1024];

static inline int xddp_emulated_rt_socket(int domain, int type, int protocol) {
  if (domain != AF_RTIPC || type != SOCK_DGRAM || protocol != IPCPROTO_XDDP) return -1;
  int sv[2];
  if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0) return -1;
  if (sv[0] >= 1024) {
    close(sv[0]);
    close(sv[1]);
    return -1;
  }
  xddp_emulated_linux_end[sv[0]] = sv[1] + 1;  // 0 = none
  return sv[0];
}
static inline int xddp_emulated_rt_setsockopt(int, int level, int name, const void*, socklen_t) {
  return level == SOL_XDDP && name == XDDP_POOLSZ ? 0 : -1;
}
static inline int xddp_emulated_rt_bind(int, const struct sockaddr*, socklen_t) { return 0; }
static inline int xddp_emulated_rt_getsockname(int fd, struct sockaddr* a, socklen_t*) {
  reinterpret_cast<sockaddr_ipc*>(a)->sipc_port = fd;
  return 0;
}
static inline ssize_t xddp_emulated_rt_sendto(int fd, const void* b, size_t n, int flags, const struct sockaddr*,
                                              socklen_t) {
  return send(fd, b, n, flags);
}
static inline ssize_t xddp_emulated_rt_recvfrom(int fd, void* b, size_t n, int flags, struct sockaddr*, socklen_t*) {
  return recv(fd, b, n, flags);
}
static inline int xddp_emulated_rt_close(int fd) {
  if (fd >= 0 && fd < 1024 && xddp_emulated_linux_end[fd]) close(xddp_emulated_linux_end[fd] - 1);
  if (fd >= 0 && fd < 1024) xddp_emulated_linux_end[fd] = 0;
  return close(fd);
}

static inline int xddp_emulated_std_open(const char* path, int flags) {
  int port;
  if (sscanf(path, "/dev/rtp%d", &port) != 1) return open(path, flags);
  if (port < 0 || port >= 1024 || !xddp_emulated_linux_end[port]) return -1;
  int fd = xddp_emulated_linux_end[port] - 1;  // handed over: the relay closes it
  xddp_emulated_linux_end[port] = 0;
  return fd;
}
static inline ssize_t xddp_emulated_std_read(int fd, void* b, size_t n) { return read(fd, b, n); }
static inline ssize_t xddp_emulated_std_write(int fd, const void* b, size_t n) { return write(fd, b, n); }
static inline int xddp_emulated_std_close(int fd) { return close(fd); }
static inline int xddp_emulated_std_pthread_create(pthread_t* t, const pthread_attr_t* a, void* (*f)(void*), void* arg) {
  return pthread_create(t, a, f, arg);
}
static inline int xddp_emulated_std_pthread_join(pthread_t t, void** r) { return pthread_join(t, r); }
