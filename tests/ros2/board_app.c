/* SPDX-License-Identifier: Apache-2.0 */
/*
 * board_app: the application on board A (or any node) in the ROS 2 bridge tests, a plain
 * client of the public ccomm C API.
 *
 *   board_app pub SIGNAL N HZ [AGO_MS]  write N values at HZ (0: as fast as the queue
 *                                 allows), never closer than half a period; with AGO_MS
 *                                 each is stamped as written AGO_MS before it is handed to
 *                                 ccomm (a value produced earlier: a known production age)
 *   board_app watch SIGNAL N SEC  print the first N new values (state) / events within SEC
 *
 * Values are made so a reader can check each element and the write time: element 0 is
 * the sample number k (1..N), for double signals element 1 (or the scalar) is the ccomm
 * write time (CLOCK_MONOTONIC ns, exact in a double), every other element i is
 * k * 1000 + i (bool: (k + i) % 2). watch prints one line per value:
 *   seq STATUS age_ns source_time_ns v0 v1 ...
 * and exits 0 if it saw N values, 1 otherwise.
 */
#include <ccomm/ccomm.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void fill(const ccomm_signal_desc* d, uint64_t k, int64_t t, unsigned char* buf) {
  for (uint32_t i = 0; i < d->count; ++i) {
    int64_t v = (int64_t)(k * 1000 + i);
    if (i == 0) v = (int64_t)k;
    switch (d->type) {
      case CCOMM_DOUBLE: {
        double x = (d->count == 1 || i == 1) ? (double)t : (double)v;
        memcpy(buf + 8 * i, &x, 8);
        break;
      }
      case CCOMM_FLOAT: { float x = (float)v; memcpy(buf + 4 * i, &x, 4); break; }
      case CCOMM_INT32: case CCOMM_UINT32: { int32_t x = (int32_t)v; memcpy(buf + 4 * i, &x, 4); break; }
      case CCOMM_INT64: { memcpy(buf + 8 * i, &v, 8); break; }
      case CCOMM_BOOL: buf[i] = (unsigned char)((k + i) % 2); break;
    }
  }
}

static void print_value(const ccomm_signal_desc* d, const unsigned char* buf) {
  for (uint32_t i = 0; i < d->count; ++i) {
    switch (d->type) {
      case CCOMM_DOUBLE: { double x; memcpy(&x, buf + 8 * i, 8); printf(" %.17g", x); break; }
      case CCOMM_FLOAT: { float x; memcpy(&x, buf + 4 * i, 4); printf(" %.9g", (double)x); break; }
      case CCOMM_INT32: { int32_t x; memcpy(&x, buf + 4 * i, 4); printf(" %d", x); break; }
      case CCOMM_UINT32: { uint32_t x; memcpy(&x, buf + 4 * i, 4); printf(" %u", x); break; }
      case CCOMM_INT64: { int64_t x; memcpy(&x, buf + 8 * i, 8); printf(" %lld", (long long)x); break; }
      case CCOMM_BOOL: printf(" %d", buf[i]); break;
    }
  }
  printf("\n");
}

static void sleep_until(int64_t t) {
  ccomm_sleep_until(t);
}

int main(int argc, char** argv) {
  if (argc < 5 || argc > 6 || (strcmp(argv[1], "pub") && strcmp(argv[1], "watch")) ||
      (argc == 6 && strcmp(argv[1], "pub"))) {
    fprintf(stderr, "usage: board_app pub SIGNAL N HZ [AGO_MS] | board_app watch SIGNAL N SECONDS\n");
    return 2;
  }
  ccomm_client* c;
  int rc = ccomm_open(NULL, 0, &c);
  if (rc) { fprintf(stderr, "board_app: open: %s\n", ccomm_strerror(rc)); return 1; }
  ccomm_signal s = ccomm_find(c, argv[2]);
  ccomm_signal_desc d;
  if (s < 0 || ccomm_describe(c, s, &d)) { fprintf(stderr, "board_app: no signal %s\n", argv[2]); return 1; }
  long n = atol(argv[3]);
  double arg = atof(argv[4]);
  unsigned char buf[4096];
  if (d.value_bytes > sizeof buf) return 1;
  if (!strcmp(argv[1], "pub")) {
    int64_t period = arg > 0 ? (int64_t)(1e9 / arg) : 0, next = ccomm_now();
    const int64_t ago = argc == 6 ? (int64_t)(atof(argv[5]) * 1e6) : 0;
    long written = 0;
    for (long k = 1; k <= n; ++k) {
      if (period) {
        sleep_until(next);
        /* A late wake-up does not catch up with back-to-back writes: two values of a
           state signal microseconds apart are a burst no reader can tell apart (last value
           wins). Writes stay at least half a period apart, so the stream stays 1 kHz-like. */
        int64_t now = ccomm_now();
        next = next + period > now + period / 2 ? next + period : now + period / 2;
      }
      int64_t t = ccomm_now() - ago;
      ccomm_set_time(c, t);  /* the value's ccomm write time is exactly t */
      fill(&d, (uint64_t)k, t, buf);
      for (;;) {
        rc = ccomm_write(c, s, buf, d.value_bytes);
        if (rc != CCOMM_E_FULL && rc != CCOMM_E_BUSY) break;
        ccomm_sleep_until(ccomm_now() + 1000000);
      }
      if (rc) { fprintf(stderr, "board_app: write %ld: %s\n", k, ccomm_strerror(rc)); break; }
      ++written;
    }
    printf("written %ld\n", written);
    ccomm_close(c);
    return written == n ? 0 : 1;
  }
  /* watch */
  int64_t end = ccomm_now() + (int64_t)(arg * 1e9);
  uint64_t last_seq = 0;
  ccomm_info info;
  if (!d.is_event && ccomm_read(c, s, buf, d.value_bytes, &info) >= 0) last_seq = info.seq;
  long seen = 0;
  while (seen < n && ccomm_now() < end) {
    ccomm_wait(c, 50);
    for (;;) {
      int st = ccomm_read(c, s, buf, d.value_bytes, &info);
      if (st < 0) { fprintf(stderr, "board_app: read: %s\n", ccomm_strerror(st)); return 1; }
      if (st == CCOMM_EMPTY || st == CCOMM_NEVER || info.seq == last_seq) break;
      last_seq = info.seq;
      printf("%llu %s %lld %llu", (unsigned long long)info.seq, ccomm_strerror(st),
             (long long)info.age_ns, (unsigned long long)info.source_time_ns);
      print_value(&d, buf);
      fflush(stdout);
      ++seen;
      if (!d.is_event) break;
    }
  }
  ccomm_close(c);
  return seen >= n ? 0 : 1;
}
