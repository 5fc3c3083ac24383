// SPDX-License-Identifier: Apache-2.0
// manyboards_app: the application of one board in the many-board test and benchmark
// (tests/manyboards). Public libccomm API only.
//
//   manyboards_app --node NAME --rate HZ --seconds S [--drain-ms 500] [--prio P]
//                  [--start-at T]   (CLOCK_MONOTONIC ns of cycle 0: every board the same)
//                  [--latency 0]    (no receiver thread: no latency samples, less load)
//
// Control thread (SCHED_FIFO P if given), every cycle: writes each signal produced on
// this node (value = cycle number, 1, 2, ...), ccomm_flush() (one frame per destination
// per cycle), then reads every consumed signal and follows its freshness: fresh -> stale
// and stale -> fresh transitions with their time, and for each stale transition the
// signal's age when first read stale (what an application sees when a producer dies).
// Receiver thread (SCHED_FIFO P-1): ccomm_wait() and, for each consumed signal whose
// sequence changed, one one-way latency sample (now - the producer's source time: all
// namespaces of one host share CLOCK_MONOTONIC).
// After S seconds and the drain time it prints one JSON line with the counters of every
// signal (ccomm_get_signal_stats), the transitions and the latency percentiles.
#include <ccomm/ccomm.h>

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#define kMaxSignals 4096
#define kMaxSamples (1 << 21)
#define kMaxEvents 64

typedef struct {
  ccomm_signal id;
  const char* name;
  int stale;                 // last status seen by the control thread
  int64_t fresh_ns, stale_ns; // time of the last transitions
  uint64_t to_stale, to_fresh;
  int64_t max_stale_age_ns;  // largest age at the first stale read (≈ stale_after + reader delay)
  int64_t stale_at[kMaxEvents], fresh_at[kMaxEvents];
  uint64_t last_seq_reader;  // receiver thread
  double last_value;
} Consumed;

static Consumed g_consumed[kMaxSignals];
static ccomm_signal g_produced[kMaxSignals];
static int g_nconsumed, g_nproduced;
static int64_t g_samples[kMaxSamples];
static uint64_t g_nsamples;
static atomic_int g_stop;

static int cmp_i64(const void* a, const void* b) {
  int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
  return (x > y) - (x < y);
}

static void set_fifo(int prio) {
  int32_t err[3];
  if (prio > 0 && ccomm_realtime_setup(-1, 0, prio, err) != 0)
    fprintf(stderr, "manyboards_app: SCHED_FIFO %d: %s (continuing)\n", prio, strerror(-err[2]));
}

typedef struct {
  const char* node;
  int prio;
} ReaderArgs;

static void* reader_main(void* arg) {
  const ReaderArgs* a = arg;
  set_fifo(a->prio > 1 ? a->prio - 1 : 0);
  ccomm_client* c;
  if (ccomm_open(a->node, 0, &c) != 0) return NULL;
  while (!atomic_load(&g_stop)) {
    ccomm_wait(c, 20);
    int64_t now = ccomm_now();
    for (int i = 0; i < g_nconsumed; i++) {
      Consumed* s = &g_consumed[i];
      double v;
      ccomm_info info;
      int st = ccomm_read_double(c, s->id, &v, &info);
      if (st < 0 || info.seq == 0 || info.seq == s->last_seq_reader) continue;
      s->last_seq_reader = info.seq;
      if (g_nsamples < kMaxSamples) g_samples[g_nsamples++] = now - (int64_t)info.source_time_ns;
    }
  }
  ccomm_close(c);
  return NULL;
}

static void usage(void) {
  fputs("usage: manyboards_app --node NAME --rate HZ --seconds S [--drain-ms MS] [--prio P]\n"
        "                      [--start-at CLOCK_MONOTONIC_NS] [--latency 0|1]\n"
        "One board's application in the many-board test: writes the node's produced signals\n"
        "every cycle (value = cycle number), follows the freshness of the consumed ones and\n"
        "their one-way latency, then prints one JSON line of counters.\n", stderr);
  exit(2);
}

static void sleep_until(int64_t t) {
  while (ccomm_sleep_until(t) == 1) {
  }
}

int main(int argc, char** argv) {
  const char* node = NULL;
  double rate = 1000, seconds = 10;
  int drain_ms = 500, prio = 0;
  int64_t start_at = 0;
  int latency = 1;
  for (int i = 1; i + 1 < argc + 1; i += 2) {
    if (i + 1 >= argc) usage();
    const char *a = argv[i], *v = argv[i + 1];
    if (!strcmp(a, "--node")) node = v;
    else if (!strcmp(a, "--rate")) rate = atof(v);
    else if (!strcmp(a, "--seconds")) seconds = atof(v);
    else if (!strcmp(a, "--drain-ms")) drain_ms = atoi(v);
    else if (!strcmp(a, "--prio")) prio = atoi(v);
    else if (!strcmp(a, "--start-at")) start_at = atoll(v);
    else if (!strcmp(a, "--latency")) latency = atoi(v);
    else usage();
  }
  if (!node || rate <= 0 || seconds <= 0) usage();
  int32_t err[3];
  if (prio > 0 && ccomm_realtime_setup(-1, 1, 0, err) != 0)
    fprintf(stderr, "manyboards_app: memory lock: %s (continuing)\n", strerror(-err[1]));

  ccomm_client* c;
  int r = ccomm_open(node, CCOMM_OPEN_BATCH, &c);
  if (r != 0) {
    fprintf(stderr, "manyboards_app: ccomm_open(%s): %s\n", node, ccomm_strerror(r));
    return 1;
  }
  int n = ccomm_signal_count(c);
  for (ccomm_signal s = 0; s < n && s < kMaxSignals; s++) {
    ccomm_signal_desc d;
    if (ccomm_describe(c, s, &d) != 0) continue;
    if (d.produced_here) g_produced[g_nproduced++] = s;
    if (d.consumed_here) {
      Consumed* x = &g_consumed[g_nconsumed++];
      x->id = s;
      x->name = d.name;
      x->stale = -1;
    }
  }

  set_fifo(prio);
  ReaderArgs ra = {node, prio};
  pthread_t reader;
  if (latency && pthread_create(&reader, NULL, reader_main, &ra) != 0) {
    fputs("manyboards_app: cannot start the receiver thread\n", stderr);
    return 1;
  }
  const int64_t period = (int64_t)(1e9 / rate);
  const int64_t start = start_at > 0 ? start_at : ccomm_now() + 100000000;
  const uint64_t cycles = (uint64_t)(seconds * rate + 0.5);
  uint64_t write_errors = 0, late = 0;
  static int64_t late_at[kMaxEvents], late_by[kMaxEvents];  // cycle, ns: the first late cycles
  for (uint64_t k = 0; k < cycles + (uint64_t)drain_ms * 1000000 / (uint64_t)period; k++) {
    int64_t t = start + (int64_t)k * period;
    sleep_until(t);
    int64_t lateness = ccomm_now() - t;
    if (lateness > period / 2) {  // this flush comes less than half a period after the last
      if (late < kMaxEvents) late_at[late] = (int64_t)k, late_by[late] = lateness;
      late++;
    }
    if (k < cycles) {
      for (int i = 0; i < g_nproduced; i++)
        if (ccomm_write_double(c, g_produced[i], (double)(k + 1)) != 0) write_errors++;
      if (ccomm_flush(c) != 0) write_errors++;
    }
    int64_t now = ccomm_now();
    for (int i = 0; i < g_nconsumed; i++) {
      Consumed* s = &g_consumed[i];
      double v;
      ccomm_info info;
      int st = ccomm_read_double(c, s->id, &v, &info);
      if (st < 0) continue;
      if (st == CCOMM_FRESH) s->last_value = v;
      // Freshness is followed from the first fresh value on and only while producers
      // write (every app writes the same cycles, from the common --start-at).
      if (k >= cycles) continue;
      if (s->stale == -1) {
        if (st == CCOMM_FRESH) s->stale = 0;
        continue;
      }
      int stale = st != CCOMM_FRESH;
      if (s->stale == 0 && stale) {
        if (s->to_stale < kMaxEvents) s->stale_at[s->to_stale] = now;
        s->to_stale++;
        s->stale_ns = now;
        if (info.age_ns > s->max_stale_age_ns) s->max_stale_age_ns = info.age_ns;
      } else if (s->stale == 1 && !stale) {
        if (s->to_fresh < kMaxEvents) s->fresh_at[s->to_fresh] = now;
        s->to_fresh++;
        s->fresh_ns = now;
      }
      s->stale = stale;
    }
  }
  // The drain above is counted in cycles: an app the host held back runs them without
  // sleeping and can end before a producer held back longer sent its last values. So go
  // on reading, up to 5 x drain_ms of wall time from here (a starved app and ccommd need
  // seconds on a saturated host), until every consumed signal holds the last value
  // (cycles), fresh or already stale, and its ccommd took every value it wrote (sent or
  // coalesced); ccommd's counters go on counting anyway.
  for (const int64_t until = ccomm_now() + 5 * (int64_t)drain_ms * 1000000; ccomm_now() < until;) {
    int pending = 0;
    for (int i = 0; i < g_nconsumed; i++) {
      Consumed* s = &g_consumed[i];
      double v;
      ccomm_info info;
      if (s->last_value == (double)cycles) continue;
      const int st = ccomm_read_double(c, s->id, &v, &info);
      // Stale: no newer write came (the safe value, if the signal had one, is not a value).
      if (st == CCOMM_FRESH || (st == CCOMM_STALE && !(info.flags & CCOMM_INFO_SAFE_VALUE))) s->last_value = v;
      pending += s->last_value != (double)cycles;
    }
    for (int i = 0; i < g_nproduced; i++) {  // and its own last values taken by its ccommd
      ccomm_signal_stats st;
      if (ccomm_get_signal_stats(c, g_produced[i], &st) == 0) pending += st.tx + st.coalesced != st.writes;
    }
    if (!pending) break;
    sleep_until(ccomm_now() + 1000000);
  }
  atomic_store(&g_stop, 1);
  if (latency) pthread_join(reader, NULL);

  qsort(g_samples, g_nsamples, sizeof g_samples[0], cmp_i64);
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  printf("{\"cpu_s\":%.3f,", ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6);
  printf("\"node\":\"%s\",\"cycles\":%llu,\"late_cycles\":%llu,\"write_errors\":%llu,\"samples\":%llu,"
         "\"p50_ns\":%lld,\"p99_ns\":%lld,\"produced\":{",
         node, (unsigned long long)cycles, (unsigned long long)late, (unsigned long long)write_errors,
         (unsigned long long)g_nsamples, (long long)(g_nsamples ? g_samples[g_nsamples / 2] : -1),
         (long long)(g_nsamples ? g_samples[g_nsamples * 99 / 100] : -1));
  for (int i = 0; i < g_nproduced; i++) {
    ccomm_signal_desc d;
    ccomm_signal_stats st;
    ccomm_describe(c, g_produced[i], &d);
    ccomm_get_signal_stats(c, g_produced[i], &st);
    printf("%s\"%s\":{\"writes\":%llu,\"tx\":%llu,\"coalesced\":%llu,\"write_errors\":%llu}", i ? "," : "", d.name,
           (unsigned long long)st.writes, (unsigned long long)st.tx, (unsigned long long)st.coalesced,
           (unsigned long long)st.write_errors);
  }
  printf("},\"late\":[");
  for (uint64_t e = 0; e < late && e < kMaxEvents; e++) printf("%s[%lld,%lld]", e ? "," : "", (long long)late_at[e], (long long)late_by[e]);
  printf("],\"consumed\":{");
  for (int i = 0; i < g_nconsumed; i++) {
    Consumed* s = &g_consumed[i];
    ccomm_signal_stats st;
    ccomm_get_signal_stats(c, s->id, &st);
    printf("%s\"%s\":{\"rx\":%llu,\"lost\":%llu,\"daemon_stale\":%d,\"last_value\":%.0f,\"to_stale\":%llu,"
           "\"to_fresh\":%llu,\"max_stale_age_ns\":%lld,\"stale_at\":[",
           i ? "," : "", s->name, (unsigned long long)st.rx, (unsigned long long)st.lost, st.stale, s->last_value,
           (unsigned long long)s->to_stale, (unsigned long long)s->to_fresh, (long long)s->max_stale_age_ns);
    for (uint64_t e = 0; e < s->to_stale && e < kMaxEvents; e++) printf("%s%lld", e ? "," : "", (long long)s->stale_at[e]);
    printf("],\"fresh_at\":[");
    for (uint64_t e = 0; e < s->to_fresh && e < kMaxEvents; e++) printf("%s%lld", e ? "," : "", (long long)s->fresh_at[e]);
    printf("]}");
  }
  printf("}}\n");
  ccomm_close(c);
  return 0;
}
