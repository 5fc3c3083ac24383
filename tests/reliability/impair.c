/* SPDX-License-Identifier: Apache-2.0 */
/*
 * impair: a user-space netem. Bridges two interfaces (AF_PACKET, every EtherType) and
 * applies loss, duplication, reordering, corruption and delay/jitter to ccomm's frames
 * (its EtherType, or IPv4/UDP to its port); everything else (ARP...) passes untouched.
 *
 * Why not tc netem: kernels built without CONFIG_NET_SCH_NETEM (like the one these tests
 * were first run on) have none, and a user-space bridge also counts exactly what it did
 * to each frame, which the tests compare with ccommd's counters.
 *
 * Commands on stdin, one per line:
 *   set loss=P dup=P reorder=P corrupt=P delay=MS jitter=MS   (percentages; any subset,
 *                                           the others keep their value)
 *   stats                                   print the counters as one JSON line
 *   pause / resume                          hold (count and drop) every ccomm frame, so
 *                                           that the test can read both daemons while
 *                                           nothing is in flight; both print the stats
 *   quit
 * Netem semantics: loss drops; dup sends a second copy; corrupt flips one random bit
 * of the ccomm frame (for UDP the checksum is cleared, as if corruption happened
 * before it was computed: the frame reaches ccommd); delay + uniform(0, jitter) holds
 * the frame back; reorder sends that share of frames at once, ahead of delayed ones.
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <linux/if_ether.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define SNAP 1600
#define QCAP 8192

struct params {
  double loss, dup, reorder, corrupt, delay_ms, jitter_ms;
};

struct counters {
  unsigned long long in, other, held, dropped, duplicated, corrupted, reordered, delivered, overflow, send_errors;
};

struct qframe {
  uint64_t due;
  int dir; /* 0: came in on a, goes out on b; 1: the other way */
  uint16_t len;
  uint8_t data[SNAP];
};

static struct qframe* queue;     /* binary min-heap on due */
static unsigned qn;
static struct params P;
static int paused;
static struct counters C[2];
static int fds[2], ifidx[2];
static unsigned ethertype = 0x88B5, udp_port = 47800;
static uint64_t rng = 0x9E3779B97F4A7C15ULL;

static uint64_t rnd(void) {
  rng ^= rng >> 12;
  rng ^= rng << 25;
  rng ^= rng >> 27;
  return rng * 0x2545F4914F6CDD1DULL;
}
static int chance(double pct) { return pct > 0 && (double)(rnd() % 1000000) < pct * 10000.0; }

static uint64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static void heap_swap(unsigned a, unsigned b) {
  struct qframe t = queue[a];
  queue[a] = queue[b];
  queue[b] = t;
}

static void push(const uint8_t* f, size_t len, int dir, uint64_t due) {
  if (qn == QCAP) {
    C[dir].overflow++;
    return;
  }
  unsigned i = qn++;
  queue[i].due = due;
  queue[i].dir = dir;
  queue[i].len = (uint16_t)len;
  memcpy(queue[i].data, f, len);
  while (i > 0 && queue[(i - 1) / 2].due > queue[i].due) {
    heap_swap(i, (i - 1) / 2);
    i = (i - 1) / 2;
  }
}

static void pop(void) {
  queue[0] = queue[--qn];
  unsigned i = 0;
  for (;;) {
    unsigned l = 2 * i + 1, r = l + 1, m = i;
    if (l < qn && queue[l].due < queue[m].due) m = l;
    if (r < qn && queue[r].due < queue[m].due) m = r;
    if (m == i) break;
    heap_swap(i, m);
    i = m;
  }
}

/* Offset of the ccomm frame inside an Ethernet frame, or 0 if it is not ccomm traffic.
 * *udp_csum is set to the offset of the UDP checksum field for UDP frames. */
static size_t ccomm_offset(const uint8_t* f, size_t len, size_t* udp_csum) {
  *udp_csum = 0;
  if (len < 14) return 0;
  unsigned et = (unsigned)f[12] << 8 | f[13];
  if (et == ethertype) return 14;
  if (et != ETH_P_IP || len < 14 + 20 + 8) return 0;
  const uint8_t* ip = f + 14;
  size_t ihl = (size_t)(ip[0] & 0x0f) * 4;
  if ((ip[0] >> 4) != 4 || ip[9] != 17 || ihl < 20 || len < 14 + ihl + 8) return 0;
  if ((ip[6] & 0x3f) || ip[7]) return 0; /* fragments: not ccomm's (frames fit one datagram) */
  const uint8_t* udp = ip + ihl;
  if (((unsigned)udp[2] << 8 | udp[3]) != udp_port) return 0;
  *udp_csum = 14 + ihl + 6;
  return 14 + ihl + 8;
}

static void handle(int in, uint8_t* f, size_t len) {
  struct counters* c = &C[in];
  size_t csum = 0, off = ccomm_offset(f, len, &csum);
  /* Checksums of locally sent UDP may be left to offload (partial); a frame re-sent
   * through AF_PACKET would arrive with a wrong one. IPv4 allows "no checksum" (0). */
  if (csum) f[csum] = f[csum + 1] = 0;
  if (!off || off >= len) {
    c->other++;
    push(f, len, in, 0);
    return;
  }
  c->in++;
  if (paused) {
    c->held++;
    return;
  }
  if (chance(P.loss)) {
    c->dropped++;
    return;
  }
  int copies = 1;
  if (chance(P.dup)) {
    copies = 2;
    c->duplicated++;
  }
  if (chance(P.corrupt)) {
    size_t bit = rnd() % ((len - off) * 8);
    f[off + bit / 8] ^= (uint8_t)(1u << (bit % 8));
    c->corrupted++;
  }
  uint64_t now = now_ns();
  for (int k = 0; k < copies; ++k) {
    uint64_t delay = 0;
    if (k == 0 && P.delay_ms > 0 && chance(P.reorder)) {
      c->reordered++; /* sent at once, overtaking the delayed ones */
    } else {
      double ms = P.delay_ms + (P.jitter_ms > 0 ? P.jitter_ms * (double)(rnd() % 1000001) / 1e6 : 0);
      delay = (uint64_t)(ms * 1e6);
    }
    push(f, len, in, now + delay);
  }
}

static int open_if(const char* name, int* idx) {
  int fd = socket(AF_PACKET, SOCK_RAW | SOCK_CLOEXEC, htons(ETH_P_ALL));
  if (fd < 0) {
    perror("impair: AF_PACKET (needs CAP_NET_RAW)");
    exit(1);
  }
  *idx = (int)if_nametoindex(name);
  if (!*idx) {
    fprintf(stderr, "impair: no interface %s\n", name);
    exit(1);
  }
  struct sockaddr_ll sll;
  memset(&sll, 0, sizeof sll);
  sll.sll_family = AF_PACKET;
  sll.sll_protocol = htons(ETH_P_ALL);
  sll.sll_ifindex = *idx;
  if (bind(fd, (struct sockaddr*)&sll, sizeof sll)) {
    perror("impair: bind");
    exit(1);
  }
  int one = 1;
#ifdef PACKET_IGNORE_OUTGOING
  setsockopt(fd, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof one);
#endif
  (void)one;
  int buf = 8 << 20;
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buf, sizeof buf);
  setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &buf, sizeof buf);
  return fd;
}

static void print_stats(void) {
  const char* dir[2] = {"a2b", "b2a"};
  printf("{");
  for (int d = 0; d < 2; ++d) {
    const struct counters* c = &C[d];
    printf("%s\"%s\":{\"in\":%llu,\"held\":%llu,\"dropped\":%llu,\"duplicated\":%llu,\"corrupted\":%llu,\"reordered\":%llu,"
           "\"delivered\":%llu,\"overflow\":%llu,\"send_errors\":%llu,\"other\":%llu}",
           d ? "," : "", dir[d], c->in, c->held, c->dropped, c->duplicated, c->corrupted, c->reordered, c->delivered,
           c->overflow, c->send_errors, c->other);
  }
  printf(",\"queued\":%u}\n", qn);
  fflush(stdout);
}

static void command(char* line) {
  if (!strncmp(line, "stats", 5)) {
    print_stats();
  } else if (!strncmp(line, "pause", 5)) {
    paused = 1;  /* ccomm frames are counted as held and not forwarded */
    print_stats();
  } else if (!strncmp(line, "resume", 6)) {
    print_stats();  /* final count of this pause, then frames flow again */
    paused = 0;
  } else if (!strncmp(line, "quit", 4)) {
    print_stats();
    exit(0);
  } else if (!strncmp(line, "set", 3)) {
    for (char* tok = strtok(line + 3, " \t\n"); tok; tok = strtok(NULL, " \t\n")) {
      char* eq = strchr(tok, '=');
      if (!eq) continue;
      *eq = 0;
      double v = atof(eq + 1);
      if (!strcmp(tok, "loss")) P.loss = v;
      else if (!strcmp(tok, "dup")) P.dup = v;
      else if (!strcmp(tok, "reorder")) P.reorder = v;
      else if (!strcmp(tok, "corrupt")) P.corrupt = v;
      else if (!strcmp(tok, "delay")) P.delay_ms = v;
      else if (!strcmp(tok, "jitter")) P.jitter_ms = v;
      else fprintf(stderr, "impair: unknown parameter %s\n", tok);
    }
    printf("{\"set\":{\"loss\":%g,\"dup\":%g,\"reorder\":%g,\"corrupt\":%g,\"delay\":%g,\"jitter\":%g}}\n", P.loss,
           P.dup, P.reorder, P.corrupt, P.delay_ms, P.jitter_ms);
    fflush(stdout);
  } else if (line[0] != '\n' && line[0]) {
    fprintf(stderr, "impair: unknown command %s", line);
  }
}

int main(int argc, char** argv) {
  const char *a = NULL, *b = NULL;
  static const struct option opts[] = {{"a", 1, 0, 'a'},    {"b", 1, 0, 'b'},     {"ethertype", 1, 0, 'e'},
                                       {"port", 1, 0, 'p'}, {"seed", 1, 0, 's'}, {0, 0, 0, 0}};
  int ch;
  while ((ch = getopt_long(argc, argv, "", opts, NULL)) != -1) {
    switch (ch) {
      case 'a': a = optarg; break;
      case 'b': b = optarg; break;
      case 'e': ethertype = (unsigned)strtoul(optarg, NULL, 0); break;
      case 'p': udp_port = (unsigned)strtoul(optarg, NULL, 0); break;
      case 's': rng = strtoull(optarg, NULL, 0) | 1; break;
      default: return 2;
    }
  }
  if (!a || !b) {
    fprintf(stderr, "usage: impair --a IF --b IF [--ethertype N] [--port N] [--seed N] < commands\n");
    return 2;
  }
  queue = calloc(QCAP, sizeof *queue);
  if (!queue) return 1;
  fds[0] = open_if(a, &ifidx[0]);
  fds[1] = open_if(b, &ifidx[1]);
  printf("{\"ready\":true}\n");
  fflush(stdout);

  char line[512];
  size_t line_len = 0;
  uint8_t f[SNAP];
  for (;;) {
    int timeout = -1;
    uint64_t now = now_ns();
    while (qn && queue[0].due <= now) {
      const struct qframe* q = &queue[0];
      size_t csum = 0;
      int ours = ccomm_offset(q->data, q->len, &csum) != 0;
      if (send(fds[1 - q->dir], q->data, q->len, 0) == (ssize_t)q->len) {
        if (ours) C[q->dir].delivered++;
      } else if (ours) {
        C[q->dir].send_errors++;
      }
      pop();
    }
    if (qn) {
      uint64_t d = queue[0].due - now;
      timeout = (int)(d / 1000000) + 1;
      if (d < 1000000) timeout = 0;  /* due within a millisecond: poll without sleeping */
    }
    struct pollfd pfd[3] = {{fds[0], POLLIN, 0}, {fds[1], POLLIN, 0}, {0, POLLIN, 0}};
    int n = poll(pfd, 3, timeout);
    if (n < 0 && errno != EINTR) {
      perror("impair: poll");
      return 1;
    }
    for (int i = 0; i < 2; ++i) {
      if (!(pfd[i].revents & POLLIN)) continue;
      for (int burst = 0; burst < 64; ++burst) {
        struct sockaddr_ll from;
        socklen_t fl = sizeof from;
        ssize_t len = recvfrom(fds[i], f, sizeof f, MSG_DONTWAIT, (struct sockaddr*)&from, &fl);
        if (len <= 0) break;
        if (from.sll_pkttype == PACKET_OUTGOING) continue; /* our own sends */
        handle(i, f, (size_t)len);
      }
    }
    if (pfd[2].revents & (POLLIN | POLLHUP)) {
      ssize_t r = read(0, line + line_len, sizeof line - 1 - line_len);
      if (r <= 0) {
        print_stats();
        return 0;
      }
      line_len += (size_t)r;
      line[line_len] = 0;
      char* nl;
      while ((nl = strchr(line, '\n'))) {
        *nl = 0;
        command(line);
        size_t used = (size_t)(nl - line) + 1;
        memmove(line, nl + 1, line_len - used + 1);
        line_len -= used;
      }
      if (line_len == sizeof line - 1) line_len = 0; /* overlong line: drop it */
    }
  }
}
