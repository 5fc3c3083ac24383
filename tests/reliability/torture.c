/* SPDX-License-Identifier: Apache-2.0 */
/*
 * torture: self-checking clients for the crash-safety and fault tests, on the public C
 * API (libccomm) only.
 *
 *   torture write SIGNAL [--rate HZ]     write self-consistent values as fast as asked
 *   torture check SIGNAL [--duration S]  validate every value read; exit 1 at the first
 *                                        corrupt one
 *   torture stale SIGNAL [--timeout S]   wait for fresh values, then measure how long
 *                                        after the last arrival the read turns stale
 *
 * A value is an int64 array of COUNT >= 2 elements: elements 0..COUNT-2 all hold
 * (writer_id << 40 | n) and the last holds a checksum of it. A torn or mixed copy (two
 * writers, or a half-written slot) breaks the equality or the checksum. Per writer, n
 * only grows; events must arrive in order (gaps are allowed: loss is counted elsewhere).
 *
 * Clients survive the daemon: CCOMM_E_NOENT (no segment yet) and CCOMM_E_RETIRED (the
 * daemon replaced the segment) make them reopen. Output: JSON lines.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "ccomm/ccomm.h"

#define MAX_COUNT 128
#define MAX_WRITERS 4096

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int s) { (void)s; g_stop = 1; }

static uint64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static uint64_t checksum(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  return x ^ (x >> 33) ^ 0x5ca1ab1eULL;
}

struct conn {
  const char* node;
  const char* name;
  ccomm_client* c;
  ccomm_signal s;
  ccomm_signal_desc d;
  unsigned reopens;
};

/* (Re)attaches, waiting for ccommd as long as it takes (or until stopped). */
static int attach(struct conn* k) {
  if (k->c) {
    ccomm_close(k->c);
    k->c = NULL;
    k->reopens++;
  }
  while (!g_stop) {
    int r = ccomm_open(k->node, 0, &k->c);
    if (r == 0) {
      k->s = ccomm_find(k->c, k->name);
      if (k->s < 0 || ccomm_describe(k->c, k->s, &k->d) != 0) {
        fprintf(stderr, "torture: no signal %s\n", k->name);
        exit(2);
      }
      if (k->d.type != CCOMM_INT64 || k->d.count < 2 || k->d.count > MAX_COUNT) {
        fprintf(stderr, "torture: %s must be int64 with 2..%d elements\n", k->name, MAX_COUNT);
        exit(2);
      }
      return 0;
    }
    if (r != CCOMM_E_NOENT && r != CCOMM_E_RETIRED) {
      fprintf(stderr, "torture: ccomm_open: %s\n", ccomm_strerror(r));
      exit(2);
    }
    usleep(5000);
  }
  return -1;
}

static int cmd_write(struct conn* k, double rate) {
  const uint64_t id = (uint64_t)getpid() & 0xffffff;
  int64_t v[MAX_COUNT];
  uint64_t n = 0, ok = 0, busy = 0, full = 0;
  const uint64_t period = rate > 0 ? (uint64_t)(1e9 / rate) : 0;
  uint64_t next = now_ns(), report = next + 1000000000ull;
  if (attach(k)) return 0;
  while (!g_stop) {
    uint64_t tag = id << 40 | (++n & ((1ull << 40) - 1));
    for (uint32_t i = 0; i + 1 < k->d.count; ++i) v[i] = (int64_t)tag;
    v[k->d.count - 1] = (int64_t)checksum(tag);
    int r = ccomm_write(k->c, k->s, v, k->d.value_bytes);
    if (r == 0) ok++;
    else if (r == CCOMM_E_BUSY) busy++;
    else if (r == CCOMM_E_FULL) full++;
    else if (r == CCOMM_E_RETIRED) { if (attach(k)) break; }
    else { fprintf(stderr, "torture: write: %s\n", ccomm_strerror(r)); return 1; }
    if (period) {
      next += period;
      uint64_t t = now_ns();
      if (next > t) {
        ccomm_sleep_until((int64_t)next);
      } else if (t - next > 100 * period) {
        next = t;  /* fell far behind (stopped, descheduled): do not burst */
      }
    }
    uint64_t t = now_ns();
    if (t >= report) {
      printf("{\"write\":\"%s\",\"id\":%" PRIu64 ",\"ok\":%" PRIu64 ",\"busy\":%" PRIu64 ",\"full\":%" PRIu64
             ",\"reopens\":%u}\n", k->name, id, ok, busy, full, k->reopens);
      fflush(stdout);
      report = t + 1000000000ull;
    }
  }
  printf("{\"write\":\"%s\",\"id\":%" PRIu64 ",\"ok\":%" PRIu64 ",\"busy\":%" PRIu64 ",\"full\":%" PRIu64
         ",\"reopens\":%u,\"final\":true}\n", k->name, id, ok, busy, full, k->reopens);
  return 0;
}

struct writer_state {
  uint64_t id, last;
};
static struct writer_state writers[MAX_WRITERS];
static unsigned nwriters;

static uint64_t* last_of(uint64_t id) {
  for (unsigned i = 0; i < nwriters; ++i)
    if (writers[i].id == id) return &writers[i].last;
  if (nwriters == MAX_WRITERS) nwriters = 0; /* forget old writers: they are long dead */
  writers[nwriters].id = id;
  writers[nwriters].last = 0;
  return &writers[nwriters++].last;
}

static int cmd_check(struct conn* k, double duration) {
  int64_t v[MAX_COUNT];
  uint64_t reads = 0, values = 0, fresh = 0, stale = 0, never = 0, busy = 0, order = 0, detected = 0;
  uint64_t last_seq = 0;
  const uint64_t end = duration > 0 ? now_ns() + (uint64_t)(duration * 1e9) : UINT64_MAX;
  uint64_t report = now_ns() + 1000000000ull;
  if (attach(k)) return 0;
  const int is_event = k->d.is_event;
  while (!g_stop && now_ns() < end) {
    ccomm_info info;
    memset(v, 0, sizeof v);
    int r = ccomm_read(k->c, k->s, v, k->d.value_bytes, &info);
    reads++;
    if (r == CCOMM_E_RETIRED) { if (attach(k)) break; continue; }
    if (r == CCOMM_E_BUSY) { busy++; continue; }
    if (r == CCOMM_E_CORRUPT) { detected++; continue; }  /* damaged in shared memory: refused */
    if (r < 0) { fprintf(stderr, "torture: read: %s\n", ccomm_strerror(r)); return 1; }
    if (r == CCOMM_NEVER) { never++; continue; }
    if (r == CCOMM_EMPTY) { usleep(200); continue; }
    if (r == CCOMM_STALE) stale++;
    else fresh++;
    if (info.flags & CCOMM_INFO_SAFE_VALUE) continue;  /* configured constant, not a write */
    /* State: the same value is read again until a new one comes; check each new one. */
    if (!is_event && info.seq == last_seq) {
      usleep(20); /* poll, do not hog a core */
      continue;
    }
    last_seq = info.seq;
    values++;
    uint64_t tag = (uint64_t)v[0];
    int bad = checksum(tag) != (uint64_t)v[k->d.count - 1];
    for (uint32_t i = 1; i + 1 < k->d.count; ++i) bad |= (uint64_t)v[i] != tag;
    if (bad) {
      printf("{\"check\":\"%s\",\"corrupt\":true,\"seq\":%" PRIu64 ",\"v0\":%" PRIu64 ",\"v1\":%" PRIu64
             ",\"vlast\":%" PRIu64 ",\"values\":%" PRIu64 "}\n",
             k->name, info.seq, (uint64_t)v[0], (uint64_t)v[1], (uint64_t)v[k->d.count - 1], values);
      fflush(stdout);
      return 1;
    }
    uint64_t* last = last_of(tag >> 40);
    uint64_t n = tag & ((1ull << 40) - 1);
    if (n <= *last) order++;  /* same writer went back: a replay or a reordering */
    *last = n;
    uint64_t t = now_ns();
    if (t >= report) {
      printf("{\"check\":\"%s\",\"values\":%" PRIu64 ",\"order_violations\":%" PRIu64 ",\"reopens\":%u}\n",
             k->name, values, order, k->reopens);
      fflush(stdout);
      report = t + 1000000000ull;
    }
  }
  printf("{\"check\":\"%s\",\"final\":true,\"reads\":%" PRIu64 ",\"values\":%" PRIu64 ",\"fresh\":%" PRIu64
         ",\"stale\":%" PRIu64 ",\"never\":%" PRIu64 ",\"busy\":%" PRIu64 ",\"order_violations\":%" PRIu64
         ",\"writers\":%u,\"reopens\":%u,\"detected\":%" PRIu64 ",\"corrupt\":false}\n",
         k->name, reads, values, fresh, stale, never, busy, order, nwriters, k->reopens, detected);
  return 0;
}

/* Any type: the test only needs the status. */
static int cmd_stale(const char* node, const char* name, double timeout) {
  ccomm_client* c = NULL;
  int r = ccomm_open(node, 0, &c);
  if (r) { fprintf(stderr, "torture: ccomm_open: %s\n", ccomm_strerror(r)); return 2; }
  ccomm_signal s = ccomm_find(c, name);
  ccomm_signal_desc d;
  if (s < 0 || ccomm_describe(c, s, &d)) { fprintf(stderr, "torture: no signal %s\n", name); return 2; }
  uint8_t buf[8192];
  const uint64_t end = now_ns() + (uint64_t)(timeout * 1e9);
  uint64_t fresh_reads = 0, last_arrival = 0;
  int64_t max_fresh_age = 0;
  while (!g_stop && now_ns() < end) {
    ccomm_info info;
    r = ccomm_read(c, s, buf, d.value_bytes, &info);
    uint64_t t = now_ns();
    if (r == CCOMM_FRESH) {
      fresh_reads++;
      last_arrival = t - (uint64_t)info.age_ns;
      if (info.age_ns > max_fresh_age) max_fresh_age = info.age_ns;
    } else if (r == CCOMM_STALE && fresh_reads > 0) {
      /* The read that first says stale: the ages the API reported (exact: no read may say
       * fresh beyond stale_after_ms) and the wall time since the last value arrived
       * (includes this reader's polling and scheduling). */
      printf("{\"stale\":\"%s\",\"stale_after_ms\":%u,\"detected_after_ms\":%.3f,\"max_fresh_age_ms\":%.3f,"
             "\"first_stale_age_ms\":%.3f,\"safe_value\":%s,\"fresh_reads\":%" PRIu64 "}\n",
             name, d.stale_after_ms, (double)(t - last_arrival) / 1e6, (double)max_fresh_age / 1e6,
             (double)info.age_ns / 1e6, (info.flags & CCOMM_INFO_SAFE_VALUE) ? "true" : "false", fresh_reads);
      ccomm_close(c);
      return 0;
    }
    ccomm_sleep_until(ccomm_now() + 100000); /* 0.1 ms: the resolution of the figure */
  }
  printf("{\"stale\":\"%s\",\"timeout\":true,\"fresh_reads\":%" PRIu64 "}\n", name, fresh_reads);
  ccomm_close(c);
  return 1;
}

int main(int argc, char** argv) {
  static const struct option opts[] = {{"node", 1, 0, 'n'},    {"rate", 1, 0, 'r'},
                                       {"duration", 1, 0, 'd'}, {"timeout", 1, 0, 't'},
                                       {0, 0, 0, 0}};
  const char* node = NULL;
  double rate = 0, duration = 0, timeout = 10;
  int ch;
  while ((ch = getopt_long(argc, argv, "n:r:d:t:", opts, NULL)) != -1) {
    switch (ch) {
      case 'n': node = optarg; break;
      case 'r': rate = atof(optarg); break;
      case 'd': duration = atof(optarg); break;
      case 't': timeout = atof(optarg); break;
      default: return 2;
    }
  }
  if (argc - optind != 2) {
    fprintf(stderr, "usage: torture [--node N] write|check|stale SIGNAL [--rate HZ] [--duration S] [--timeout S]\n");
    return 2;
  }
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGINT, &sa, NULL);
  setvbuf(stdout, NULL, _IOLBF, 0);
  const char* cmd = argv[optind];
  struct conn k = {node, argv[optind + 1], NULL, -1, {0}, 0};
  if (!strcmp(cmd, "write")) return cmd_write(&k, rate);
  if (!strcmp(cmd, "check")) return cmd_check(&k, duration);
  if (!strcmp(cmd, "stale")) return cmd_stale(node, argv[optind + 1], timeout);
  fprintf(stderr, "torture: unknown command %s\n", cmd);
  return 2;
}
