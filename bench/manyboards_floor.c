// SPDX-License-Identifier: Apache-2.0
// manyboards_floor: the floor of the many-board test. One instance per board (network
// namespace): every cycle it sends ONE frame to its own multicast group (raw Ethernet
// MAC 03:63:63:6d:00:ID, or UDP group BASE+ID) and receives the frames of the boards
// listed with --from, like ccommd with fanout="multicast" but with no ccomm code at all.
// It tells whether the host can move N boards x RATE frames at all, and what one-way
// latency and CPU per board the bare sockets cost in the same topology.
//
//   manyboards_floor --transport raw|udp --iface eth0 --id K --from 1,2,3 --rate 1000
//                    --seconds 10 [--ip 10.43.0.K] [--group-base 239.255.67.0] [--port P]
//
// Prints one JSON line: {"id":K,"sent":..,"rx":{"1":n,...},"lost":..,"p50_ns":..,
// "p99_ns":..,"cpu_s":..,"late_cycles":..}. Exit 0, or 1 on a setup error.
#include <arpa/inet.h>
#include <errno.h>
#include <linux/filter.h>
#include <linux/if_packet.h>
#include <net/ethernet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define kEtherType 0x88B6 /* not ccomm's 0x88B5: the floor never confuses a daemon */
#define kMaxBoards 64
#define kMaxSamples (1 << 20)
#define kMagic 0x464c4f52u /* "FLOR" */

typedef struct {
  uint32_t magic;
  uint32_t sender;
  uint64_t seq;
  int64_t send_ns;
  uint8_t pad[40]; /* 64-byte payload: about a ccomm frame with 1-2 entries */
} FloorFrame;

static int64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void die(const char* what) {
  fprintf(stderr, "manyboards_floor: %s: %s\n", what, strerror(errno));
  exit(1);
}

static int cmp_i64(const void* a, const void* b) {
  int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
  return (x > y) - (x < y);
}

static void usage(void) {
  fputs("usage: manyboards_floor --transport raw|udp --iface IF --id K --from A,B,... --rate HZ\n"
        "                        --seconds S [--ip ADDR] [--group-base 239.255.67.0] [--port 47900]\n"
        "One board of the many-board floor: sends one frame per cycle to its own multicast\n"
        "group, receives the groups of the boards in --from; prints a JSON line of counts,\n"
        "one-way latency and CPU time.\n", stderr);
  exit(2);
}

int main(int argc, char** argv) {
  const char* transport = "raw";
  const char* iface = "eth0";
  const char* ip = NULL;
  const char* group_base = "239.255.67.0";
  int id = -1, port = 47900;
  double rate = 1000, seconds = 10;
  int from[kMaxBoards], nfrom = 0;
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!v) usage();
    if (!strcmp(a, "--transport")) transport = v;
    else if (!strcmp(a, "--iface")) iface = v;
    else if (!strcmp(a, "--ip")) ip = v;
    else if (!strcmp(a, "--group-base")) group_base = v;
    else if (!strcmp(a, "--id")) id = atoi(v);
    else if (!strcmp(a, "--port")) port = atoi(v);
    else if (!strcmp(a, "--rate")) rate = atof(v);
    else if (!strcmp(a, "--seconds")) seconds = atof(v);
    else if (!strcmp(a, "--from")) {
      char buf[512];
      snprintf(buf, sizeof buf, "%s", v);
      for (char* t = strtok(buf, ","); t && nfrom < kMaxBoards; t = strtok(NULL, ",")) from[nfrom++] = atoi(t);
    } else usage();
    i++;
  }
  if (id < 0 || id >= kMaxBoards || rate <= 0 || seconds <= 0) usage();
  int raw = !strcmp(transport, "raw");
  if (!raw && strcmp(transport, "udp")) usage();
  unsigned ifindex = if_nametoindex(iface);
  if (!ifindex) die(iface);

  int fd;
  struct sockaddr_ll to_ll;
  struct sockaddr_in to_in;
  in_addr_t base = inet_addr(group_base);
  if (raw) {
    fd = socket(AF_PACKET, SOCK_DGRAM, htons(kEtherType));
    if (fd < 0) die("socket(AF_PACKET)");
    struct sockaddr_ll bind_ll = {.sll_family = AF_PACKET, .sll_protocol = htons(kEtherType), .sll_ifindex = (int)ifindex};
    if (bind(fd, (struct sockaddr*)&bind_ll, sizeof bind_ll) < 0) die("bind");
    for (int k = 0; k < nfrom; k++) {  // what a daemon would do: tell the NIC which groups it wants
      struct packet_mreq mr = {.mr_ifindex = (int)ifindex, .mr_type = PACKET_MR_MULTICAST, .mr_alen = 6,
                               .mr_address = {0x03, 0x63, 0x63, 0x6d, 0x00, (unsigned char)from[k]}};
      if (setsockopt(fd, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &mr, sizeof mr) < 0) die("PACKET_ADD_MEMBERSHIP");
    }
    // Like ccommd: a kernel socket filter passes only the groups wanted (the bridge floods
    // raw multicast to every port), so other boards' frames never wake this process.
    // Classic BPF on the frame's sender byte (offset 4, little-endian low byte).
    struct sock_filter code[kMaxBoards + 3];
    int nc = 0;
    code[nc++] = (struct sock_filter)BPF_STMT(BPF_LD | BPF_B | BPF_ABS, 4);
    for (int k = 0; k < nfrom; k++)  // jump to "accept" (the last instruction) on a match
      code[nc++] = (struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, (uint32_t)from[k],
                                                (uint8_t)(nfrom - k), 0);
    code[nc++] = (struct sock_filter)BPF_STMT(BPF_RET | BPF_K, 0);
    code[nc++] = (struct sock_filter)BPF_STMT(BPF_RET | BPF_K, 0xFFFF);
    struct sock_fprog prog = {.len = (unsigned short)nc, .filter = code};
    if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &prog, sizeof prog) < 0) die("SO_ATTACH_FILTER");
    memset(&to_ll, 0, sizeof to_ll);
    to_ll.sll_family = AF_PACKET;
    to_ll.sll_protocol = htons(kEtherType);
    to_ll.sll_ifindex = (int)ifindex;
    to_ll.sll_halen = 6;
    unsigned char mac[6] = {0x03, 0x63, 0x63, 0x6d, 0x00, (unsigned char)id};
    memcpy(to_ll.sll_addr, mac, 6);
  } else {
    if (!ip) usage();
    fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) die("socket(AF_INET)");
    int one = 1, zero = 0, ttl = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in any = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port), .sin_addr = {INADDR_ANY}};
    if (bind(fd, (struct sockaddr*)&any, sizeof any) < 0) die("bind");
    struct in_addr local = {inet_addr(ip)};
    if (setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &local, sizeof local) < 0) die("IP_MULTICAST_IF");
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &zero, sizeof zero);
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
    for (int k = 0; k < nfrom; k++) {
      struct ip_mreq m = {.imr_multiaddr = {htonl(ntohl(base) + (uint32_t)from[k])}, .imr_interface = local};
      if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &m, sizeof m) < 0) die("IP_ADD_MEMBERSHIP");
    }
    memset(&to_in, 0, sizeof to_in);
    to_in.sin_family = AF_INET;
    to_in.sin_port = htons((uint16_t)port);
    to_in.sin_addr.s_addr = htonl(ntohl(base) + (uint32_t)id);
  }

  static int64_t samples[kMaxSamples];
  uint64_t nsamples = 0, sent = 0, rx[kMaxBoards] = {0}, next_seq[kMaxBoards] = {0}, lost = 0, other = 0;
  uint64_t late_cycles = 0;
  int wanted[kMaxBoards] = {0};
  for (int k = 0; k < nfrom; k++) wanted[from[k]] = 1;
  const int64_t period = (int64_t)(1e9 / rate);
  const int64_t start = now_ns() + 200000000;  // 200 ms for every board to join first
  const int64_t end = start + (int64_t)(seconds * 1e9);
  const int64_t drain_end = end + 200000000;
  int64_t next = start;
  FloorFrame f;
  memset(&f, 0, sizeof f);
  for (;;) {
    int64_t t = now_ns();
    if (t >= drain_end) break;
    if (t >= next && next < end) {
      f.magic = kMagic;
      f.sender = (uint32_t)id;
      f.seq = sent;
      f.send_ns = t;
      ssize_t w = raw ? sendto(fd, &f, sizeof f, 0, (struct sockaddr*)&to_ll, sizeof to_ll)
                      : sendto(fd, &f, sizeof f, 0, (struct sockaddr*)&to_in, sizeof to_in);
      if (w == (ssize_t)sizeof f) sent++;
      next += period;
      if (now_ns() >= next) late_cycles++;
      continue;
    }
    int64_t wait_ns = (next < end ? next : drain_end) - t;
    struct pollfd p = {.fd = fd, .events = POLLIN};
    struct timespec ts = {(time_t)(wait_ns / 1000000000), (long)(wait_ns % 1000000000)};
    if (ppoll(&p, 1, &ts, NULL) <= 0) continue;  // woken by a frame or at the next send time
    for (;;) {
      FloorFrame in;
      struct sockaddr_ll from_ll;
      socklen_t fl = sizeof from_ll;
      ssize_t r = recvfrom(fd, &in, sizeof in, MSG_DONTWAIT, raw ? (struct sockaddr*)&from_ll : NULL, raw ? &fl : NULL);
      if (r < 0) break;
      int64_t rt = now_ns();
      if (raw && from_ll.sll_pkttype == PACKET_OUTGOING) continue;
      if (r != (ssize_t)sizeof in || in.magic != kMagic || in.sender >= kMaxBoards || !wanted[in.sender]) {
        other++;
        continue;
      }
      rx[in.sender]++;
      if (in.seq > next_seq[in.sender]) lost += in.seq - next_seq[in.sender];
      next_seq[in.sender] = in.seq + 1;
      if (nsamples < kMaxSamples) samples[nsamples++] = rt - in.send_ns;
    }
  }
  qsort(samples, nsamples, sizeof samples[0], cmp_i64);
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  double cpu = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6;
  printf("{\"id\":%d,\"transport\":\"%s\",\"sent\":%llu,\"rx\":{", id, transport, (unsigned long long)sent);
  for (int k = 0; k < nfrom; k++) printf("%s\"%d\":%llu", k ? "," : "", from[k], (unsigned long long)rx[from[k]]);
  printf("},\"lost\":%llu,\"other\":%llu,\"late_cycles\":%llu,\"samples\":%llu,\"p50_ns\":%lld,\"p99_ns\":%lld,"
         "\"cpu_s\":%.3f}\n",
         (unsigned long long)lost, (unsigned long long)other, (unsigned long long)late_cycles,
         (unsigned long long)nsamples, (long long)(nsamples ? samples[nsamples / 2] : -1),
         (long long)(nsamples ? samples[nsamples * 99 / 100] : -1), cpu);
  return 0;
}
