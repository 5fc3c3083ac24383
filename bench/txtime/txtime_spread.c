// SPDX-License-Identifier: Apache-2.0
// Departure spread of frames sent at set instants (issue 29, "send on the cycle"): a sender
// aims each UDP frame at an instant of a fixed cycle, a receiver takes the kernel's receive
// timestamp (SO_TIMESTAMPNS, CLOCK_REALTIME; on a veth pair that is the departure, one host,
// one clock) and reports how late each frame left. Modes:
//   sleep   clock_nanosleep to the instant, then send (what a user-space cycle can do)
//   txtime  hand the frame to the kernel LEAD_US early with SO_TXTIME (launch time = the
//           instant, CLOCK_TAI): only an ETF (or fq) qdisc holds it until then
//   txtime_spread send|recv IP PORT MODE COUNT PERIOD_US [LEAD_US]
// recv prints: n, lateness p50/p99/max/min in us, spread (max - min) in us.
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <linux/net_tstamp.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#ifndef SO_TXTIME
#define SO_TXTIME 61
#define SCM_TXTIME SO_TXTIME
#endif

#include "txtime_common.h"


int main(int argc, char** argv) {
  if (argc < 7) {
    fprintf(stderr, "usage: txtime_spread send|recv IP PORT sleep|txtime COUNT PERIOD_US [LEAD_US]\n");
    return 2;
  }
  const int sending = strcmp(argv[1], "send") == 0, txtime = strcmp(argv[4], "txtime") == 0;
  const long count = atol(argv[5]), period_ns = atol(argv[6]) * 1000;
  const long lead_ns = argc > 7 ? atol(argv[7]) * 1000 : 1000000;
  struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)atoi(argv[3]))};
  inet_pton(AF_INET, argv[2], &a.sin_addr);
  int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (!sending) {
    int on = 1;
    setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
    if (bind(fd, (struct sockaddr*)&a, sizeof a)) { perror("bind"); return 1; }
    int64_t* late = calloc((size_t)count, sizeof *late);
    long n = 0;
    struct timeval tv = {5, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    while (n < count) {
      int64_t intended;
      char ctl[256];
      struct iovec iov = {&intended, sizeof intended};
      struct msghdr m = {.msg_iov = &iov, .msg_iovlen = 1, .msg_control = ctl, .msg_controllen = sizeof ctl};
      if (recvmsg(fd, &m, 0) != sizeof intended) break;
      for (struct cmsghdr* c = CMSG_FIRSTHDR(&m); c; c = CMSG_NXTHDR(&m, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
          struct timespec ts;
          memcpy(&ts, CMSG_DATA(c), sizeof ts);
          late[n++] = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec - intended;
        }
      }
    }
    if (n == 0) { printf("n=0\n"); return 1; }
    qsort(late, (size_t)n, sizeof *late, Cmp);
    printf("n=%ld late_us p50=%.1f p99=%.1f max=%.1f min=%.1f spread_us=%.1f\n", n, late[n / 2] / 1e3,
           late[n * 99 / 100] / 1e3, late[n - 1] / 1e3, late[0] / 1e3, (late[n - 1] - late[0]) / 1e3);
    return 0;
  }
  if (txtime) {
    struct sock_txtime cfg = {.clockid = CLOCK_TAI, .flags = 0};
    if (setsockopt(fd, SOL_SOCKET, SO_TXTIME, &cfg, sizeof cfg)) { perror("SO_TXTIME"); return 3; }
  }
  // Instants on CLOCK_REALTIME (the receiver's timestamps); TAI = REALTIME + its offset.
  const int64_t tai_minus_real = Ns(CLOCK_TAI) - Ns(CLOCK_REALTIME);
  const int64_t start = (Ns(CLOCK_REALTIME) / period_ns + 10) * period_ns;
  for (long i = 0; i < count; ++i) {
    const int64_t intended = start + i * period_ns;
    const int64_t wake = txtime ? intended - lead_ns : intended;
    struct timespec w = {wake / 1000000000, wake % 1000000000};
    while (clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &w, NULL) == EINTR) {}
    struct iovec iov = {(void*)&intended, sizeof intended};
    char ctl[CMSG_SPACE(sizeof(uint64_t))] = {0};
    struct msghdr m = {.msg_name = &a, .msg_namelen = sizeof a, .msg_iov = &iov, .msg_iovlen = 1};
    if (txtime) {
      m.msg_control = ctl;
      m.msg_controllen = sizeof ctl;
      struct cmsghdr* c = CMSG_FIRSTHDR(&m);
      c->cmsg_level = SOL_SOCKET;
      c->cmsg_type = SCM_TXTIME;
      c->cmsg_len = CMSG_LEN(sizeof(uint64_t));
      const uint64_t launch = (uint64_t)(intended + tai_minus_real);
      memcpy(CMSG_DATA(c), &launch, sizeof launch);
    }
    if (sendmsg(fd, &m, 0) < 0) { perror("sendmsg"); return 1; }
  }
  return 0;
}
