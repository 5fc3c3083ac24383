// SPDX-License-Identifier: Apache-2.0
// Departures of a board's own ccomm data frames against the instants of its send cycle
// (issue 29, "send on the cycle"; docs/performance.md, section 13). A packet socket on the
// sending board sees each outgoing frame as the driver gets it (dev_queue_xmit_nit: after
// the qdisc, so after ETF held it), with the kernel's timestamp (SO_TIMESTAMPNS,
// CLOCK_REALTIME). Each departure is mapped onto the clock the cycle is aligned on and
// compared with the nearest instant k * cycle + phase:
//   txtime_departures IFACE ETHERTYPE CYCLE_US PHASE_US mono|tai SECONDS [SAMPLES_FILE]
// Only data frames (no heartbeat, no summary flag) count. Prints one line:
//   n=N late_us p50=.. p99=.. max=.. min=.. spread_us=..
// (late = departure - instant; negative = before the instant). The cycle must be longer
// than twice the largest lateness (each departure is judged against its nearest instant).
#include <arpa/inet.h>
#include <errno.h>
#include <linux/if_packet.h>
#include <net/ethernet.h>
#include <net/if.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "txtime_common.h"


int main(int argc, char** argv) {
  if (argc < 7) {
    fprintf(stderr, "usage: txtime_departures IFACE ETHERTYPE CYCLE_US PHASE_US mono|tai SECONDS [SAMPLES_FILE]\n");
    return 2;
  }
  const unsigned ifindex = if_nametoindex(argv[1]);
  const int ethertype = (int)strtol(argv[2], NULL, 0);
  const int64_t cycle = atoll(argv[3]) * 1000, phase = atoll(argv[4]) * 1000;
  const int tai = strcmp(argv[5], "tai") == 0;
  const double seconds = atof(argv[6]);
  if (!ifindex || cycle <= 0) {
    fprintf(stderr, "txtime_departures: no interface %s, or no cycle\n", argv[1]);
    return 2;
  }
  // ETH_P_ALL: a packet socket sees outgoing frames only as a tap of every protocol.
  int fd = socket(AF_PACKET, SOCK_RAW, htons(ETH_P_ALL));
  if (fd < 0) {
    perror("socket(AF_PACKET)");
    return 1;
  }
  struct sockaddr_ll sll = {.sll_family = AF_PACKET, .sll_protocol = htons(ETH_P_ALL), .sll_ifindex = (int)ifindex};
  if (bind(fd, (struct sockaddr*)&sll, sizeof sll)) {
    perror("bind");
    return 1;
  }
  int on = 1;
  setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
  struct timeval tv = {0, 200000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  // Realtime stamps onto the cycle's clock: mono = real - (real - mono); tai = real + (tai - real).
  const int64_t m0 = Ns(CLOCK_MONOTONIC), r = Ns(CLOCK_REALTIME), m1 = Ns(CLOCK_MONOTONIC);
  const int64_t real_minus_mono = r - (m0 + m1) / 2;
  const int64_t tai_minus_real = Ns(CLOCK_TAI) - Ns(CLOCK_REALTIME);
  const int64_t shift = tai ? (tai_minus_real + 500000000) / 1000000000 * 1000000000 : -real_minus_mono;
  const size_t cap = 1000000;
  int64_t* late = malloc(cap * sizeof *late);
  size_t n = 0;
  const int64_t end = Ns(CLOCK_MONOTONIC) + (int64_t)(seconds * 1e9);
  while (Ns(CLOCK_MONOTONIC) < end && n < cap) {
    uint8_t buf[2048];
    char ctl[256];
    struct sockaddr_ll from;
    struct iovec iov = {buf, sizeof buf};
    struct msghdr m = {.msg_name = &from, .msg_namelen = sizeof from, .msg_iov = &iov, .msg_iovlen = 1,
                       .msg_control = ctl, .msg_controllen = sizeof ctl};
    const ssize_t len = recvmsg(fd, &m, 0);
    if (len < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      perror("recvmsg");
      break;
    }
    // Outgoing ccomm data frames: Ethernet header, then magic "CCMW", version, flags
    // (heartbeat 1, summary 4).
    if (from.sll_pkttype != PACKET_OUTGOING || len < 14 + 6 || ((buf[12] << 8) | buf[13]) != ethertype ||
        (buf[14 + 5] & 0x05))
      continue;
    for (struct cmsghdr* c = CMSG_FIRSTHDR(&m); c; c = CMSG_NXTHDR(&m, c)) {
      if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SO_TIMESTAMPNS) continue;
      struct timespec ts;
      memcpy(&ts, CMSG_DATA(c), sizeof ts);
      const int64_t t = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec + shift;
      int64_t d = (t - phase) % cycle;
      if (d < 0) d += cycle;
      if (d > cycle / 2) d -= cycle;
      late[n++] = d;
    }
  }
  if (argc > 7) {
    FILE* f = fopen(argv[7], "w");
    for (size_t i = 0; f && i < n; ++i) fprintf(f, "%lld\n", (long long)late[i]);
    if (f) fclose(f);
  }
  if (n == 0) {
    printf("n=0\n");
    return 1;
  }
  qsort(late, n, sizeof *late, Cmp);
  printf("n=%zu late_us p50=%.1f p99=%.1f max=%.1f min=%.1f spread_us=%.1f\n", n, late[n / 2] / 1e3,
         late[n * 99 / 100] / 1e3, late[n - 1] / 1e3, late[0] / 1e3, (late[n - 1] - late[0]) / 1e3);
  return 0;
}
