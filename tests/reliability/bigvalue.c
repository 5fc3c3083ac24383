/* SPDX-License-Identifier: Apache-2.0 */
/*
 * bigvalue: writer and checking reader of a large array signal (uint32[N], up to 64 KiB,
 * sent in fragments), on the public C API (libccomm) only.
 *
 *   bigvalue write NODE SIGNAL --first K --count N --rate HZ
 *       writes N values K, K+1, ...: every element of value n holds n
 *   bigvalue read NODE SIGNAL --duration S
 *       reads as fast as it can (200 us apart) and checks every value read is whole:
 *       all elements equal (a mix of two values would not be) and equal to the value's
 *       sequence number (the n-th write has seq n on a fresh segment)
 *
 * Output: one JSON line. Exit 1 on any torn or mismatched value, 2 on a usage/API error.
 */
#define _GNU_SOURCE
#include <inttypes.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "ccomm/ccomm.h"

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int s) { (void)s; g_stop = 1; }

static uint64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static void sleep_until(uint64_t t) {
  while (ccomm_sleep_until((int64_t)t) != 0 && !g_stop) {
  }
}

static const char* arg(int argc, char** argv, const char* name, const char* dflt) {
  for (int i = 0; i + 1 < argc; ++i)
    if (strcmp(argv[i], name) == 0) return argv[i + 1];
  return dflt;
}

int main(int argc, char** argv) {
  if (argc < 4 || (strcmp(argv[1], "write") != 0 && strcmp(argv[1], "read") != 0)) {
    fprintf(stderr, "usage: bigvalue write NODE SIGNAL --first K --count N --rate HZ\n"
                    "       bigvalue read NODE SIGNAL --duration S\n");
    return 2;
  }
  signal(SIGTERM, on_signal);
  signal(SIGINT, on_signal);
  ccomm_client* c = NULL;
  int r = ccomm_open(argv[2], 0, &c);
  if (r < 0) {
    fprintf(stderr, "bigvalue: ccomm_open %s: %s\n", argv[2], ccomm_strerror(r));
    return 2;
  }
  ccomm_signal s = ccomm_find(c, argv[3]);
  ccomm_signal_desc d;
  if (s < 0 || ccomm_describe(c, s, &d) < 0 || d.type != CCOMM_UINT32) {
    fprintf(stderr, "bigvalue: no uint32 array signal %s\n", argv[3]);
    return 2;
  }
  uint32_t* v = malloc(d.value_bytes);
  if (!v) return 2;

  if (strcmp(argv[1], "write") == 0) {
    const uint32_t first = (uint32_t)strtoul(arg(argc, argv, "--first", "1"), NULL, 10);
    const uint32_t count = (uint32_t)strtoul(arg(argc, argv, "--count", "100"), NULL, 10);
    const double rate = atof(arg(argc, argv, "--rate", "100"));
    const uint64_t period = (uint64_t)(1e9 / (rate > 0 ? rate : 100));
    uint64_t next = now_ns();
    uint32_t written = 0, errors = 0;
    for (uint32_t n = first; n < first + count && !g_stop; ++n) {
      for (uint32_t i = 0; i < d.count; ++i) v[i] = n;
      if (ccomm_write(c, s, v, d.value_bytes) == 0) ++written;
      else ++errors;
      next += period;
      sleep_until(next);
    }
    printf("{\"written\":%u,\"errors\":%u}\n", written, errors);
    ccomm_close(c);
    return errors ? 1 : 0;
  }

  const double duration = atof(arg(argc, argv, "--duration", "10"));
  const uint64_t end = now_ns() + (uint64_t)(duration * 1e9);
  uint64_t reads = 0, torn = 0, mismatch = 0, distinct = 0, last_seq = 0, went_back = 0;
  while (!g_stop && now_ns() < end) {
    ccomm_info info;
    r = ccomm_read(c, s, v, d.value_bytes, &info);
    if (r < 0) {
      fprintf(stderr, "bigvalue: read: %s\n", ccomm_strerror(r));
      return 2;
    }
    if (r == CCOMM_FRESH || r == CCOMM_STALE) {
      ++reads;
      uint32_t bad = 0;
      for (uint32_t i = 1; i < d.count; ++i) bad += v[i] != v[0];
      if (bad) {
        if (torn < 5) fprintf(stderr, "bigvalue: torn value: seq %" PRIu64 ", element 0 = %u, %u elements differ\n",
                              info.seq, v[0], bad);
        ++torn;
      } else if (v[0] != info.seq) {
        if (mismatch < 5) fprintf(stderr, "bigvalue: value %u read with seq %" PRIu64 "\n", v[0], info.seq);
        ++mismatch;
      }
      if (info.seq != last_seq) {
        if (info.seq < last_seq) ++went_back;
        ++distinct;
        last_seq = info.seq;
      }
    }
    usleep(200);
  }
  printf("{\"reads\":%" PRIu64 ",\"torn\":%" PRIu64 ",\"mismatch\":%" PRIu64 ",\"distinct\":%" PRIu64
         ",\"went_back\":%" PRIu64 ",\"last\":%" PRIu64 "}\n",
         reads, torn, mismatch, distinct, went_back, last_seq);
  ccomm_close(c);
  return torn || mismatch || went_back ? 1 : 0;
}
