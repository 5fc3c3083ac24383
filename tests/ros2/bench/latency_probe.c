/* SPDX-License-Identifier: Apache-2.0 */
/*
 * latency_probe: the measuring ends of the ROS 2 bridge benchmark (tests/ros2/bench/run).
 * Every writer puts the sample number in element 0 and its CLOCK_MONOTONIC write time in
 * element 1 of a 36-double array (board_app pub for ccomm, `dds-write` here for bare
 * DDS); every reader takes CLOCK_MONOTONIC when it has the value and records the
 * difference. All ends run on one machine (namespaces), so one clock serves all.
 *
 *   latency_probe ccomm SIGNAL N SECONDS      ccomm reader (ccomm_wait, as an app would)
 *   latency_probe dds TOPIC N SECONDS         DDS reader of std_msgs/Float64MultiArray
 *   latency_probe dds-write TOPIC N HZ        bare DDS writer, the floor of the DDS leg;
 *                                             prints its CPU time per sample
 *
 * Readers print one JSON line: {"n":..,"p50_us":..,"p90_us":..,"p99_us":..,"max_us":..}.
 */
#include <ccomm/ccomm.h>
#include <dds/dds.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "std_msgs.h"

#define COUNT 36
static double lat_us[200000];
static long nlat;

static int64_t mono(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static int cmp(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : x > y;
}

static int summary(long want) {
  qsort(lat_us, (size_t)nlat, sizeof lat_us[0], cmp);
#define Q(p) (nlat ? lat_us[(long)((nlat - 1) * (p))] : -1.0)
  printf("{\"n\":%ld,\"p50_us\":%.1f,\"p90_us\":%.1f,\"p99_us\":%.1f,\"max_us\":%.1f}\n", nlat, Q(0.5),
         Q(0.9), Q(0.99), Q(1.0));
  return nlat >= want ? 0 : 1;
}

static dds_entity_t make_topic(dds_entity_t* pp, const char* topic) {
  const char* dom = getenv("ROS_DOMAIN_ID"); /* the bridge's domain, as ROS 2 nodes do */
  *pp = dds_create_participant(dom && *dom ? (dds_domainid_t)atoi(dom) : 0, NULL, NULL);
  if (*pp < 0) { fprintf(stderr, "latency_probe: participant: %s\n", dds_strretcode(*pp)); exit(1); }
  return dds_create_topic(*pp, &std_msgs_msg_dds__Float64MultiArray__desc, topic, NULL, NULL);
}

static dds_qos_t* qos(int reader) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  /* the writer as the bridge's (keep last 1); the reader keeps all: a late reader still
     measures every sample */
  if (reader) dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
  else dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  /* XCDR1, as ROS 2 and the bridge use (writers), accepted by the reader */
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
  return q;
}

static int dds_read_mode(const char* topic, long n, double secs) {
  dds_entity_t pp, tp = make_topic(&pp, topic);
  dds_qos_t* q = qos(1);
  dds_entity_t rd = dds_create_reader(pp, tp, q, NULL);
  dds_delete_qos(q);
  dds_entity_t ws = dds_create_waitset(pp);
  dds_entity_t rc = dds_create_readcondition(rd, DDS_ANY_STATE);
  dds_waitset_attach(ws, rc, 0);
  printf("ready\n");
  fflush(stdout);
  void* buf[16] = {0};
  dds_sample_info_t si[16];
  int64_t end = mono() + (int64_t)(secs * 1e9);
  while (nlat < n && mono() < end) {
    dds_waitset_wait(ws, NULL, 0, DDS_MSECS(100));
    int got = dds_take(rd, buf, si, 16, 16);
    int64_t now = mono();
    for (int i = 0; i < got; ++i) {
      const std_msgs_msg_dds__Float64MultiArray_* s = buf[i];
      if (si[i].valid_data && s->data_._length >= 2 && nlat < (long)(sizeof lat_us / sizeof lat_us[0]))
        lat_us[nlat++] = (double)(now - (int64_t)s->data_._buffer[1]) / 1e3;
    }
    if (got > 0) dds_return_loan(rd, buf, got);
  }
  dds_delete(pp);
  return summary(n);
}

static int dds_write_mode(const char* topic, long n, double hz) {
  dds_entity_t pp, tp = make_topic(&pp, topic);
  dds_qos_t* q = qos(0);
  dds_entity_t wr = dds_create_writer(pp, tp, q, NULL);
  dds_delete_qos(q);
  /* wait for the reader */
  for (int i = 0; i < 100; ++i) {
    dds_publication_matched_status_t st;
    dds_get_publication_matched_status(wr, &st);
    if (st.current_count > 0) break;
    struct timespec ms = {0, 20000000};
    nanosleep(&ms, NULL);
  }
  struct timespec settle = {0, 500000000};
  nanosleep(&settle, NULL);
  static double data[COUNT];
  std_msgs_msg_dds__MultiArrayDimension_ dim = {"joints", COUNT, COUNT};
  std_msgs_msg_dds__Float64MultiArray_ s;
  memset(&s, 0, sizeof s);
  s.layout_.dim_._buffer = &dim;
  s.layout_.dim_._length = s.layout_.dim_._maximum = 1;
  s.data_._buffer = data;
  s.data_._length = s.data_._maximum = COUNT;
  struct rusage ru0, ru;
  getrusage(RUSAGE_SELF, &ru0); /* after discovery: only the writing is counted, as for the bridge */
  int64_t period = (int64_t)(1e9 / hz), next = mono();
  for (long k = 1; k <= n; ++k) {
    struct timespec ts = {(time_t)(next / 1000000000), (long)(next % 1000000000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
    next += period;
    for (int i = 2; i < COUNT; ++i) data[i] = (double)(k * 1000 + i);
    data[0] = (double)k;
    data[1] = (double)mono();
    dds_write(wr, &s);
  }
  nanosleep(&settle, NULL);
  /* CPU time of the whole writer process (its DDS threads too), as for the bridge */
  getrusage(RUSAGE_SELF, &ru);
#define US(t) ((double)(t).tv_sec * 1e6 + (double)(t).tv_usec)
  double cpu_us = US(ru.ru_utime) + US(ru.ru_stime) - US(ru0.ru_utime) - US(ru0.ru_stime);
  printf("{\"cpu_us_per_sample\":%.2f}\n", cpu_us / (double)n);
  dds_delete(pp);
  return 0;
}

static int ccomm_read_mode(const char* signal, long n, double secs) {
  ccomm_client* c;
  int rc = ccomm_open(NULL, 0, &c);
  if (rc) { fprintf(stderr, "latency_probe: %s\n", ccomm_strerror(rc)); return 1; }
  ccomm_signal s = ccomm_find(c, signal);
  double v[COUNT];
  ccomm_info info;
  uint64_t last = 0;
  if (ccomm_read(c, s, v, sizeof v, &info) >= 0) last = info.seq;
  printf("ready\n");
  fflush(stdout);
  int64_t end = mono() + (int64_t)(secs * 1e9);
  while (nlat < n && mono() < end) {
    ccomm_wait(c, 100);
    int st = ccomm_read(c, s, v, sizeof v, &info);
    int64_t now = mono();
    if (st == CCOMM_FRESH && info.seq != last && nlat < (long)(sizeof lat_us / sizeof lat_us[0])) {
      last = info.seq;
      lat_us[nlat++] = (double)(now - (int64_t)v[1]) / 1e3;
    }
  }
  ccomm_close(c);
  return summary(n);
}

int main(int argc, char** argv) {
  if (argc == 5 && !strcmp(argv[1], "ccomm")) return ccomm_read_mode(argv[2], atol(argv[3]), atof(argv[4]));
  if (argc == 5 && !strcmp(argv[1], "dds")) return dds_read_mode(argv[2], atol(argv[3]), atof(argv[4]));
  if (argc == 5 && !strcmp(argv[1], "dds-write")) return dds_write_mode(argv[2], atol(argv[3]), atof(argv[4]));
  fprintf(stderr, "usage: latency_probe ccomm SIGNAL N SECONDS | dds TOPIC N SECONDS | dds-write TOPIC N HZ\n");
  return 2;
}
