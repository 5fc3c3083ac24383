/* SPDX-License-Identifier: Apache-2.0 */
/*
 * flood: sends junk at ccommd -- random bytes, truncated frames and broken headers --
 * over raw Ethernet (AF_PACKET, ccommd's EtherType) or UDP (its port), batched with
 * sendmmsg, paced to a rate. Every frame it sends is one ccommd must count as
 * frames_bad (none can decode: the magic is wrong, the frame is shorter than it
 * declares, a reserved field is set, or it is empty), so a test can compare counts
 * exactly.
 *
 * It can also replay: capture N frames ccommd sends on an interface and send them again
 * (the authentication test uses this to check that replays are refused).
 *
 * Prints one JSON line: {"mode","kind","sent","errors","elapsed_s","rate"}.
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <linux/if_ether.h>
#include <linux/if_packet.h>
#include <net/ethernet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define MAX_FRAME 1472 /* ccomm's kMaxFrameSize */
#define HDR ((size_t)32)
#define POOL 4096
#define MAX_BATCH 256

static const char usage[] =
    "Usage: flood (--ifname IF | --udp IP) [OPTIONS]\n"
    "  --ifname IF        raw Ethernet on IF (needs CAP_NET_RAW)\n"
    "  --ethertype N      EtherType (default 0x88B5)\n"
    "  --dst MAC          destination MAC (default broadcast)\n"
    "  --src MAC          source MAC written into the frames (default: IF's own)\n"
    "  --udp IP           UDP to IP instead\n"
    "  --port N           UDP port (default 47800)\n"
    "  --kind K           random | truncated | badhdr | empty | mixed (default mixed)\n"
    "  --rate N           frames per second, 0 = as fast as possible (default 0)\n"
    "  --duration S       stop after S seconds (default 5)\n"
    "  --count N          stop after N frames\n"
    "  --batch N          frames per sendmmsg (default 64, max 256)\n"
    "  --seed N           random seed (default 1)\n"
    "  --replay N         raw only: capture N frames of the EtherType that this host\n"
    "                     sends on IF, then send each of them again --times times\n"
    "  --times N          replays per captured frame (default 1)\n"
    "  --capture-timeout S  give up capturing after S seconds (default 5)\n";

static uint64_t rng_state = 1;
static uint64_t rnd(void) { /* xorshift64*: fast and good enough for junk */
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return rng_state * 0x2545F4914F6CDD1DULL;
}

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

static int parse_mac(const char* s, uint8_t mac[6]) {
  unsigned v[6];
  if (sscanf(s, "%x:%x:%x:%x:%x:%x", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) != 6) return -1;
  for (int i = 0; i < 6; ++i) mac[i] = (uint8_t)v[i];
  return 0;
}

static void put16(uint8_t* p, uint16_t v) { p[0] = (uint8_t)(v >> 8); p[1] = (uint8_t)v; }
static void put32(uint8_t* p, uint32_t v) { put16(p, (uint16_t)(v >> 16)); put16(p + 2, (uint16_t)v); }

/* A plausible ccomm header: right magic and version, so the decoder gets past the
 * cheap checks. Payload declared `payload` bytes. */
static void plausible_header(uint8_t* f, uint16_t payload) {
  put32(f, 0x43434D57u);
  f[4] = 2; /* wire::kVersion (src/wire/wire.h); wire_test checks this copy */
  f[5] = 0;
  put16(f + 6, (uint16_t)(rnd() % 4));
  put32(f + 8, (uint32_t)rnd());
  put32(f + 12, (uint32_t)rnd());
  for (int i = 16; i < 24; ++i) f[i] = (uint8_t)rnd();
  put16(f + 24, (uint16_t)(payload / 32 ? payload / 32 : 1));
  put16(f + 26, payload);
  put16(f + 28, (uint16_t)(rnd() % 4));
  put16(f + 30, 0);
}

/* Fills f with one junk frame of kind k (0 random, 1 truncated, 2 bad header, 3 empty);
 * returns its length. */
static size_t make_junk(uint8_t* f, int k) {
  size_t len;
  switch (k) {
    case 3: /* nothing at all after the Ethernet header / an empty datagram */
      return 0;
    case 0: /* random bytes; first byte never 'C' so the magic can never match */
      len = 1 + rnd() % MAX_FRAME;
      for (size_t i = 0; i < len; ++i) f[i] = (uint8_t)rnd();
      if (f[0] == 'C') f[0] = 'c';
      return len;
    case 1: { /* valid-looking header and entries, cut short of the declared length */
      uint16_t payload = (uint16_t)(8 * (3 + rnd() % ((MAX_FRAME - HDR) / 8 - 3)));
      plausible_header(f, payload);
      for (size_t i = HDR; i < HDR + payload; ++i) f[i] = (uint8_t)rnd();
      return 1 + rnd() % (HDR + payload - 1); /* 1 .. declared-1 */
    }
    default: { /* complete length, but a reserved header field is set */
      uint16_t payload = (uint16_t)(8 * (rnd() % 20));
      plausible_header(f, payload);
      put16(f + 30, (uint16_t)(1 + rnd() % 0xfffe));
      for (size_t i = HDR; i < HDR + payload; ++i) f[i] = (uint8_t)rnd();
      return HDR + payload;
    }
  }
}

int main(int argc, char** argv) {
  const char *ifname = NULL, *udp_ip = NULL, *kind = "mixed";
  unsigned ethertype = 0x88B5, port = 47800, batch = 64, times = 1;
  double rate = 0, duration = 5, capture_timeout = 5;
  long long count = -1, replay = 0;
  uint8_t dst[6] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff}, src[6];
  int have_src = 0;
  static const struct option opts[] = {
      {"ifname", 1, 0, 'i'}, {"ethertype", 1, 0, 'e'}, {"dst", 1, 0, 'd'},   {"src", 1, 0, 's'},
      {"udp", 1, 0, 'u'},    {"port", 1, 0, 'p'},      {"kind", 1, 0, 'k'},  {"rate", 1, 0, 'r'},
      {"duration", 1, 0, 'D'}, {"count", 1, 0, 'c'},   {"batch", 1, 0, 'b'}, {"seed", 1, 0, 'S'},
      {"replay", 1, 0, 'R'}, {"times", 1, 0, 't'},     {"capture-timeout", 1, 0, 'T'},
      {"help", 0, 0, 'h'},   {0, 0, 0, 0}};
  int ch;
  while ((ch = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
    switch (ch) {
      case 'i': ifname = optarg; break;
      case 'e': ethertype = (unsigned)strtoul(optarg, NULL, 0); break;
      case 'd': if (parse_mac(optarg, dst)) { fprintf(stderr, "flood: bad MAC %s\n", optarg); return 2; } break;
      case 's': if (parse_mac(optarg, src)) { fprintf(stderr, "flood: bad MAC %s\n", optarg); return 2; } have_src = 1; break;
      case 'u': udp_ip = optarg; break;
      case 'p': port = (unsigned)strtoul(optarg, NULL, 0); break;
      case 'k': kind = optarg; break;
      case 'r': rate = atof(optarg); break;
      case 'D': duration = atof(optarg); break;
      case 'c': count = atoll(optarg); break;
      case 'b': batch = (unsigned)atoi(optarg); break;
      case 'S': rng_state = strtoull(optarg, NULL, 0) | 1; break;
      case 'R': replay = atoll(optarg); break;
      case 't': times = (unsigned)atoi(optarg); break;
      case 'T': capture_timeout = atof(optarg); break;
      case 'h': fputs(usage, stdout); return 0;
      default: fputs(usage, stderr); return 2;
    }
  }
  if ((!ifname) == (!udp_ip) || batch == 0 || batch > MAX_BATCH || (replay && !ifname)) {
    fputs(usage, stderr);
    return 2;
  }
  int kinds[4], nkinds = 0;
  if (!strcmp(kind, "random")) kinds[nkinds++] = 0;
  else if (!strcmp(kind, "truncated")) kinds[nkinds++] = 1;
  else if (!strcmp(kind, "badhdr")) kinds[nkinds++] = 2;
  else if (!strcmp(kind, "empty")) kinds[nkinds++] = 3;
  else if (!strcmp(kind, "mixed")) {
    /* Empty raw frames never reach a SOCK_DGRAM packet socket (the kernel drops them
     * uncounted), so the raw mix leaves them out to keep counts comparable. */
    kinds[0] = 0; kinds[1] = 1; kinds[2] = 2; kinds[3] = 3;
    nkinds = ifname ? 3 : 4;
  }
  else { fprintf(stderr, "flood: unknown kind %s\n", kind); return 2; }

  /* Frames are pre-built into a pool (Ethernet header included for raw), so sending is
   * only sendmmsg. */
  const size_t eth = ifname ? 14 : 0;
  size_t pool_n = POOL;
  uint8_t(*pool)[14 + MAX_FRAME] = calloc(POOL, sizeof *pool);
  size_t* pool_len = calloc(POOL, sizeof *pool_len);
  if (!pool || !pool_len) return 1;

  int fd;
  struct sockaddr_in sin;
  memset(&sin, 0, sizeof sin);
  if (ifname) {
    fd = socket(AF_PACKET, SOCK_RAW, htons((uint16_t)ethertype));
    if (fd < 0) { perror("flood: AF_PACKET socket (needs CAP_NET_RAW)"); return 1; }
    unsigned idx = if_nametoindex(ifname);
    if (!idx) { fprintf(stderr, "flood: no interface %s\n", ifname); return 1; }
    struct sockaddr_ll sll;
    memset(&sll, 0, sizeof sll);
    sll.sll_family = AF_PACKET;
    sll.sll_protocol = htons((uint16_t)ethertype);
    sll.sll_ifindex = (int)idx;
    if (bind(fd, (struct sockaddr*)&sll, sizeof sll)) { perror("flood: bind"); return 1; }
    if (!have_src) {
      struct ifreq ifr;
      memset(&ifr, 0, sizeof ifr);
      snprintf(ifr.ifr_name, IFNAMSIZ, "%s", ifname);
      if (ioctl(fd, SIOCGIFHWADDR, &ifr)) { perror("flood: SIOCGIFHWADDR"); return 1; }
      memcpy(src, ifr.ifr_hwaddr.sa_data, 6);
    }
  } else {
    fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) { perror("flood: socket"); return 1; }
    sin.sin_family = AF_INET;
    sin.sin_port = htons((uint16_t)port);
    if (inet_pton(AF_INET, udp_ip, &sin.sin_addr) != 1) { fprintf(stderr, "flood: bad IP %s\n", udp_ip); return 2; }
  }
  int sndbuf = 4 << 20;
  setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);

  if (replay) {
    /* Capture the frames ccommd sends, Ethernet header included. Outgoing frames only
     * reach ETH_P_ALL sockets, so this one takes everything and filters. */
    int cap = socket(AF_PACKET, SOCK_RAW, htons(ETH_P_ALL));
    if (cap < 0) { perror("flood: capture socket"); return 1; }
    struct sockaddr_ll csll;
    memset(&csll, 0, sizeof csll);
    csll.sll_family = AF_PACKET;
    csll.sll_protocol = htons(ETH_P_ALL);
    csll.sll_ifindex = (int)if_nametoindex(ifname);
    if (bind(cap, (struct sockaddr*)&csll, sizeof csll)) { perror("flood: bind capture"); return 1; }
    if ((long long)pool_n > replay) pool_n = (size_t)replay;
    size_t got = 0;
    double until = now_s() + capture_timeout;
    while (got < pool_n && now_s() < until) {
      struct pollfd pfd = {cap, POLLIN, 0};
      if (poll(&pfd, 1, 100) <= 0) continue;
      uint8_t* f = pool[got];
      struct sockaddr_ll from;
      socklen_t fl = sizeof from;
      ssize_t n = recvfrom(cap, f, 14 + MAX_FRAME, 0, (struct sockaddr*)&from, &fl);
      if (n <= 14 || from.sll_pkttype != PACKET_OUTGOING) continue; /* only what this host sent */
      if (((unsigned)f[12] << 8 | f[13]) != ethertype) continue;
      memcpy(f, dst, 6); /* resend to the configured destination */
      pool_len[got++] = (size_t)n;
    }
    close(cap);
    if (got < pool_n) {
      fprintf(stderr, "flood: captured only %zu of %zu frames\n", got, pool_n);
      return 1;
    }
    count = (long long)pool_n * times;
  } else {
    for (size_t i = 0; i < pool_n; ++i) {
      uint8_t* f = pool[i];
      if (ifname) {
        memcpy(f, dst, 6);
        memcpy(f + 6, src, 6);
        f[12] = (uint8_t)(ethertype >> 8);
        f[13] = (uint8_t)ethertype;
      }
      pool_len[i] = eth + make_junk(f + eth, kinds[i % (size_t)nkinds]);
    }
  }

  struct mmsghdr msgs[MAX_BATCH];
  struct iovec iov[MAX_BATCH];
  long long sent = 0, errors = 0;
  size_t next = 0;
  double t0 = now_s(), deadline = t0 + duration;
  if (replay) deadline = t0 + 3600;
  for (;;) {
    double t = now_s();
    if (t >= deadline || (count >= 0 && sent >= count)) break;
    unsigned n = batch;
    if (count >= 0 && (long long)n > count - sent) n = (unsigned)(count - sent);
    if (rate > 0) {
      /* Pace: this batch may start once `sent` frames are due. */
      double due = t0 + (double)sent / rate;
      if (due > t) {
        double d = due - t;
        struct timespec ts = {(time_t)d, (long)((d - (time_t)d) * 1e9)};
        nanosleep(&ts, NULL);
      }
    }
    memset(msgs, 0, sizeof(msgs[0]) * n);
    for (unsigned i = 0; i < n; ++i) {
      size_t k = replay ? (size_t)((sent + i) / times) % pool_n : next++ % pool_n;
      iov[i].iov_base = pool[k];
      iov[i].iov_len = pool_len[k];
      msgs[i].msg_hdr.msg_iov = &iov[i];
      msgs[i].msg_hdr.msg_iovlen = 1;
      if (!ifname) {
        msgs[i].msg_hdr.msg_name = &sin;
        msgs[i].msg_hdr.msg_namelen = sizeof sin;
      }
    }
    int r = sendmmsg(fd, msgs, n, 0);
    if (r < 0) {
      if (errno == ENOBUFS || errno == EAGAIN) { /* queue full: back off briefly, not an error */
        struct timespec ts = {0, 50000};
        nanosleep(&ts, NULL);
        continue;
      }
      ++errors;
      if (errors > 1000) { perror("flood: sendmmsg"); break; }
      continue;
    }
    sent += r;
  }
  double el = now_s() - t0;
  printf("{\"mode\":\"%s\",\"kind\":\"%s\",\"sent\":%lld,\"errors\":%lld,\"elapsed_s\":%.3f,\"rate\":%.0f}\n",
         ifname ? "raw" : "udp", replay ? "replay" : kind, sent, errors, el, el > 0 ? sent / el : 0.0);
  close(fd);
  return errors > 1000 ? 1 : 0;
}
