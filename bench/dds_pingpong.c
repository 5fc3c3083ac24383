/* SPDX-License-Identifier: Apache-2.0 */
/*
 * dds_pingpong: the Cyclone DDS peer (Debian's libddsc), same protocol and payloads as
 * net_floor and lcm_pingpong (bench header + N payload bytes in one octet sequence).
 *
 *   --role echo    take CCB_PING, write every message back on CCB_PONG
 *   --role ping    write CCB_PING at --rate HZ, record each answer's round trip
 *   --role source  write CCB_DATA at --rate HZ (0 = back to back), then FIN
 *   --role sink    take CCB_DATA, record now - send time (one clock: two network
 *                  namespaces of one machine share CLOCK_MONOTONIC); prints the row
 * QoS: keep-last 1 on both ends, --reliable (RELIABLE, 100 ms max blocking) or
 * best-effort (default). Waiting is a DDS waitset on a read condition, the blocking
 * receive of DDS applications. Discovery and locators come from CYCLONEDDS_URI (the
 * driver gives unicast peers and one interface; no multicast).
 * CPU: getrusage(RUSAGE_SELF) (every thread: Cyclone's receive and timer threads too)
 * over the measured window, reported as cpu_ns (echo and source on stderr).
 */
#include "bench_common.h"

#include <dds/dds.h>
#include <sys/resource.h>

#include "dds_bench.h"

#define PROBE_SEQ UINT64_MAX

enum role { R_ECHO, R_PING, R_SOURCE, R_SINK };

static const bench_rt *g_rt; /* what bench_rt_setup obtained, for the result line */

static int64_t cpu_now_ns(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ((int64_t)ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) * BENCH_NS_PER_S +
           ((int64_t)ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1000;
}

struct dds {
    dds_entity_t pp, wr, rd, ws;
};

static dds_qos_t *make_qos(int reliable)
{
    dds_qos_t *q = dds_create_qos();
    dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_MSECS(100));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    return q;
}

static void dds_check(dds_entity_t e, const char *what)
{
    if (e < 0)
        bench_die("dds_pingpong: %s: %s", what, dds_strretcode(e));
}

/* A writer on `out` and a reader (with a waitset on its read condition) on `in`;
 * either may be NULL. */
static void dds_open(struct dds *d, const char *out, const char *in, int reliable)
{
    memset(d, 0, sizeof *d);
    d->pp = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
    dds_check(d->pp, "participant (CYCLONEDDS_URI?)");
    dds_qos_t *q = make_qos(reliable);
    if (out) {
        dds_entity_t t = dds_create_topic(d->pp, &ccb_Msg_desc, out, NULL, NULL);
        dds_check(t, "topic");
        d->wr = dds_create_writer(d->pp, t, q, NULL);
        dds_check(d->wr, "writer");
    }
    if (in) {
        dds_entity_t t = dds_create_topic(d->pp, &ccb_Msg_desc, in, NULL, NULL);
        dds_check(t, "topic");
        d->rd = dds_create_reader(d->pp, t, q, NULL);
        dds_check(d->rd, "reader");
        d->ws = dds_create_waitset(d->pp);
        dds_entity_t rc = dds_create_readcondition(d->rd, DDS_ANY_STATE);
        dds_check(rc, "read condition");
        dds_check(dds_waitset_attach(d->ws, rc, 0), "waitset");
    }
    dds_delete_qos(q);
}

/* Wait until the writer has a matched reader (bounded). */
static int wait_matched(dds_entity_t wr, int64_t timeout_ns)
{
    int64_t end = bench_now_ns() + timeout_ns;
    while (bench_now_ns() < end && !bench_stop_flag) {
        dds_publication_matched_status_t st;
        if (dds_get_publication_matched_status(wr, &st) == 0 && st.current_count > 0)
            return 1;
        dds_sleepfor(DDS_MSECS(5));
    }
    return 0;
}

/* Take one message: 1 and its header fields (the payload copied to `copy` if not
 * NULL), 0 if none arrived before `deadline` (0 = block), -1 on a stop signal. */
static int take_one(struct dds *d, int64_t deadline, uint32_t *type, uint64_t *seq, int64_t *t,
                    unsigned char *copy, size_t cap, size_t *len)
{
    for (;;) {
        void *smp[1] = {NULL};
        dds_sample_info_t si[1];
        int n = dds_take(d->rd, smp, si, 1, 1);
        if (n > 0) {
            int ok = 0;
            if (si[0].valid_data) {
                const ccb_Msg *m = (const ccb_Msg *)smp[0];
                if (bench_hdr_read(m->data._buffer, m->data._length, type, seq, t) == 0) {
                    ok = 1;
                    if (copy) {
                        *len = m->data._length < cap ? m->data._length : cap;
                        memcpy(copy, m->data._buffer, *len);
                    }
                }
            }
            dds_return_loan(d->rd, smp, n);
            if (ok)
                return 1;
            continue;
        }
        if (bench_stop_flag)
            return -1;
        dds_duration_t wait = DDS_SECS(1);
        if (deadline) {
            int64_t left = deadline - bench_now_ns();
            if (left <= 0)
                return 0;
            wait = left;
        }
        dds_waitset_wait(d->ws, NULL, 0, wait);
    }
}

static void msg_init(ccb_Msg *m, size_t len)
{
    memset(m, 0, sizeof *m);
    m->data._buffer = (uint8_t *)calloc(1, len);
    if (!m->data._buffer)
        bench_die("out of memory");
    m->data._length = m->data._maximum = (uint32_t)len;
    m->data._release = false;
    for (size_t i = BENCH_HDR_SIZE; i < len; i++)
        m->data._buffer[i] = (uint8_t)i;
}

static void send_fin(struct dds *d, ccb_Msg *m, uint64_t sent)
{
    for (int k = 0; k < 3; k++) {
        bench_hdr_write(m->data._buffer, BENCH_MSG_FIN, sent, bench_now_ns());
        dds_write(d->wr, m);
        dds_sleepfor(DDS_MSECS(2));
    }
}

static void usage(FILE *f)
{
    fprintf(f, "usage: dds_pingpong --role echo|ping|source|sink [--reliable] [--idle-ms MS] [options]\n"
               "  --reliable         RELIABLE QoS (default BEST_EFFORT); keep-last 1 either way\n"
               "  --idle-ms MS       echo/sink: give up after MS without a message (default 20000)\n"
               "  --start-wait-ms MS ping/source: how long to wait for the peer (default 15000)\n"
               BENCH_COMMON_HELP);
}

static int run_echo(struct dds *d, int64_t idle_ns)
{
    static unsigned char buf[65536];
    ccb_Msg out;
    memset(&out, 0, sizeof out);
    out.data._buffer = buf;
    uint64_t echoed = 0;
    int64_t cpu0 = 0, cpu1 = 0;
    for (;;) {
        uint32_t type;
        uint64_t seq;
        int64_t t;
        size_t len = 0;
        int r = take_one(d, bench_now_ns() + idle_ns, &type, &seq, &t, buf, sizeof buf, &len);
        if (r <= 0)
            break;
        if (type == BENCH_MSG_FIN)
            break;
        if (type != BENCH_MSG_PING)
            continue;
        if (seq != PROBE_SEQ && !echoed)
            cpu0 = cpu_now_ns();
        bench_put_u32(buf + 4, BENCH_MSG_PONG);
        out.data._length = out.data._maximum = (uint32_t)len;
        dds_write(d->wr, &out);
        if (seq != PROBE_SEQ)
            echoed++;
    }
    cpu1 = cpu_now_ns();
    fprintf(stderr, "{\"role\":\"echo\",\"echoed\":%" PRIu64 ",\"cpu_ns\":%" PRId64 "}\n", echoed,
            echoed ? cpu1 - cpu0 : 0);
    return 0;
}

static int run_ping(struct dds *d, bench_opts *o, int64_t start_wait, const char *transport, int reliable)
{
    uint64_t total = o->warmup + o->count;
    bench_samples s;
    bench_samples_init(&s, (size_t)total);
    ccb_Msg m;
    msg_init(&m, BENCH_HDR_SIZE + (size_t)o->payload);
    if (!wait_matched(d->wr, start_wait))
        bench_die("dds ping: no echo matched within %" PRId64 " ms", start_wait / 1000000);
    /* Probe until the echo answers: its reader-to-writer path is matched then too. */
    int64_t give_up = bench_now_ns() + start_wait;
    int answered = 0;
    while (!answered && bench_now_ns() < give_up && !bench_stop_flag) {
        bench_hdr_write(m.data._buffer, BENCH_MSG_PING, PROBE_SEQ, bench_now_ns());
        dds_write(d->wr, &m);
        uint32_t type;
        uint64_t seq;
        int64_t t;
        int64_t until = bench_now_ns() + 20000000;
        while (take_one(d, until, &type, &seq, &t, NULL, 0, NULL) == 1)
            if (type == BENCH_MSG_PONG && seq == PROBE_SEQ) {
                answered = 1;
                break;
            }
    }
    if (!answered)
        bench_die("dds ping: no answer from an echo within %" PRId64 " ms", start_wait / 1000000);
    {   /* drain late probe answers */
        uint32_t type;
        uint64_t seq;
        int64_t t;
        while (take_one(d, bench_now_ns() + 30000000, &type, &seq, &t, NULL, 0, NULL) == 1) {
        }
    }
    int64_t period = o->rate_hz > 0 ? (int64_t)(1e9 / o->rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    uint64_t received = 0, late = 0, foreign = 0;
    int64_t cpu0 = cpu_now_ns();
    for (uint64_t i = 0; i < total && !bench_stop_flag; i++) {
        if (period)
            bench_sleep_until(t0 + (int64_t)i * period);
        int64_t ts = bench_now_ns();
        bench_hdr_write(m.data._buffer, BENCH_MSG_PING, i, ts);
        dds_write(d->wr, &m);
        int64_t until = ts + o->timeout_ns;
        for (;;) {
            uint32_t type;
            uint64_t seq;
            int64_t t;
            int r = take_one(d, until, &type, &seq, &t, NULL, 0, NULL);
            if (r <= 0)
                break;
            int64_t tr = bench_now_ns();
            if (type != BENCH_MSG_PONG || seq >= total || s.v[seq] != BENCH_MISSING) {
                foreign++;
                continue;
            }
            s.v[seq] = tr - t;
            received++;
            if (seq == i)
                break;
        }
        if (s.v[i] == BENCH_MISSING)
            late++;
    }
    int64_t cpu = cpu_now_ns() - cpu0;
    send_fin(d, &m, total);
    bench_stats st = bench_finish_samples(o, &s, total);
    char extra[320];
    /* Every round trip delivers two values (ping and pong). */
    snprintf(extra, sizeof extra,
             ",\"program\":\"dds_pingpong\",\"qos\":\"%s\",\"sent\":%" PRIu64 ",\"late\":%" PRIu64
             ",\"foreign\":%" PRIu64 ",\"cpu_ns\":%" PRId64 ",\"values\":%" PRIu64,
             reliable ? "reliable" : "best_effort", total, late, foreign, cpu, 2 * received);
    bench_print_result(o->name, transport, o, o->half ? "rtt_half" : "rtt", &st, g_rt, extra);
    return received ? BENCH_EXIT_OK : BENCH_EXIT_FAIL;
}

static int run_source(struct dds *d, bench_opts *o, int64_t start_wait)
{
    uint64_t total = o->warmup + o->count;
    ccb_Msg m;
    msg_init(&m, BENCH_HDR_SIZE + (size_t)o->payload);
    if (!wait_matched(d->wr, start_wait))
        bench_die("dds source: no sink matched within %" PRId64 " ms", start_wait / 1000000);
    dds_sleepfor(DDS_MSECS(50)); /* the reader's side of the match settles too */
    int64_t period = o->rate_hz > 0 ? (int64_t)(1e9 / o->rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    int64_t cpu0 = cpu_now_ns();
    uint64_t i;
    for (i = 0; i < total && !bench_stop_flag; i++) {
        if (period)
            bench_sleep_until(t0 + (int64_t)i * period);
        bench_hdr_write(m.data._buffer, BENCH_MSG_DATA, i, bench_now_ns());
        dds_write(d->wr, &m);
    }
    int64_t cpu = cpu_now_ns() - cpu0;
    int64_t secs = bench_now_ns() - t0;
    dds_sleepfor(DDS_MSECS(20));
    send_fin(d, &m, i);
    fprintf(stderr, "{\"role\":\"source\",\"sent\":%" PRIu64 ",\"cpu_ns\":%" PRId64 ",\"send_ns\":%" PRId64 "}\n",
            i, cpu, secs);
    return 0;
}

static int run_sink(struct dds *d, bench_opts *o, int64_t idle_ns, const char *transport, int reliable)
{
    uint64_t total = o->warmup + o->count;
    bench_samples s;
    bench_samples_init(&s, (size_t)total);
    uint64_t received = 0, foreign = 0, fin_sent = 0;
    int64_t first_rx = 0, last_rx = 0, cpu0 = 0;
    for (;;) {
        uint32_t type;
        uint64_t seq;
        int64_t t;
        int r = take_one(d, bench_now_ns() + idle_ns, &type, &seq, &t, NULL, 0, NULL);
        if (r <= 0)
            break;
        int64_t tr = bench_now_ns();
        if (type == BENCH_MSG_FIN) {
            fin_sent = seq;
            break;
        }
        if (type != BENCH_MSG_DATA || seq >= total || s.v[seq] != BENCH_MISSING) {
            foreign++;
            continue;
        }
        if (!received) {
            first_rx = tr;
            cpu0 = cpu_now_ns();
        }
        last_rx = tr;
        s.v[seq] = tr - t;
        received++;
    }
    int64_t cpu = received ? cpu_now_ns() - cpu0 : 0;
    bench_stats st = bench_finish_samples(o, &s, total);
    double rx_rate = last_rx > first_rx ? (double)(received - 1) * 1e9 / (double)(last_rx - first_rx) : 0;
    char extra[320];
    snprintf(extra, sizeof extra,
             ",\"program\":\"dds_pingpong\",\"qos\":\"%s\",\"sent\":%" PRIu64 ",\"foreign\":%" PRIu64
             ",\"cpu_ns\":%" PRId64 ",\"values\":%" PRIu64 ",\"received_total\":%" PRIu64
             ",\"rx_values_per_s\":%.0f",
             reliable ? "reliable" : "best_effort", fin_sent, foreign, cpu, received, received, rx_rate);
    bench_print_result(o->name, transport, o, "one_way", &st, g_rt, extra);
    return received ? BENCH_EXIT_OK : BENCH_EXIT_FAIL;
}

int main(int argc, char **argv)
{
    bench_opts o;
    bench_opts_defaults(&o, "dds_rtt", 8, 10000);
    o.rate_hz = 1000;
    int have_role = 0, reliable = 0;
    enum role role = R_ECHO;
    int64_t idle = 20000000000LL, start_wait = 15000000000LL;
    enum { OPT_ROLE = 0x200, OPT_RELIABLE, OPT_IDLE, OPT_START };
    static const struct option longopts[] = {BENCH_COMMON_LONGOPTS,
                                             {"role", required_argument, 0, OPT_ROLE},
                                             {"reliable", no_argument, 0, OPT_RELIABLE},
                                             {"idle-ms", required_argument, 0, OPT_IDLE},
                                             {"start-wait-ms", required_argument, 0, OPT_START},
                                             {0, 0, 0, 0}};
    static const char *const roles[] = {"echo", "ping", "source", "sink", NULL}; /* enum role */
    int opt;
    while ((opt = bench_next_opt(argc, argv, longopts, &o, usage)) != -1) {
        switch (opt) {
        case OPT_ROLE:
            role = (enum role)bench_choice_opt(argv, optarg, roles);
            have_role = 1;
            break;
        case OPT_RELIABLE: reliable = 1; break;
        case OPT_IDLE: idle = bench_ms_opt(argv, optarg, 0); break;
        case OPT_START: start_wait = bench_ms_opt(argv, optarg, 0); break;
        }
    }
    if (!have_role) {
        usage(stderr);
        return BENCH_EXIT_USAGE;
    }
    const char *transport = reliable ? "dds_reliable" : "dds_best_effort";
    /* Before the participant exists, so Cyclone's threads (its receive thread is on the
     * measured path) inherit the CPU and the priority. */
    static bench_rt rt;
    rt = bench_rt_setup(o.cpu[0], o.prio, !o.no_mlock);
    g_rt = &rt;
    struct dds d;
    switch (role) {
    case R_ECHO: dds_open(&d, "CCB_PONG", "CCB_PING", reliable); break;
    case R_PING: dds_open(&d, "CCB_PING", "CCB_PONG", reliable); break;
    case R_SOURCE: dds_open(&d, "CCB_DATA", NULL, reliable); break;
    case R_SINK: dds_open(&d, NULL, "CCB_DATA", reliable); break;
    }
    bench_install_stop_handlers();
    int rc;
    switch (role) {
    case R_ECHO: rc = run_echo(&d, idle); break;
    case R_PING: rc = run_ping(&d, &o, start_wait, transport, reliable); break;
    case R_SOURCE: rc = run_source(&d, &o, start_wait); break;
    default: rc = run_sink(&d, &o, idle, transport, reliable); break;
    }
    dds_delete(d.pp);
    return rc;
}
