/* SPDX-License-Identifier: Apache-2.0 */
/*
 * lcm_pingpong: the LCM peer, same protocol and payloads as net_floor's ping/echo
 * (bench header + N payload bytes), over LCM's UDP multicast transport.
 *
 *   --role echo   subscribe CCB_PING, republish every message on CCB_PONG
 *   --role ping   publish on CCB_PING at --rate HZ, record the round trip of each
 *                 answer on CCB_PONG (later than --timeout-ms = lost)
 * Messages are published as raw byte buffers (lcm_publish), not lcm-gen types: for
 * an array of doubles the generated encoder is a byte swap per element, far below
 * what is measured here, and raw buffers keep the peer free of generated code.
 * Waiting uses lcm_get_fileno() + ppoll() + lcm_handle(), LCM's documented way to
 * wait with a deadline.
 */
#include "bench_common.h"

#include <lcm/lcm.h>
#include <poll.h>

#define DEFAULT_URL "udpm://239.255.76.67:7667?ttl=1"
#define PROBE_SEQ UINT64_MAX
#define CH_PING "CCB_PING"
#define CH_PONG "CCB_PONG"

enum role { R_ECHO, R_PING };

struct ctx {
    lcm_t *lcm;
    bench_opts o;
    enum role role;
    int persist;
    int fin;
    uint64_t echoed;
    /* ping side */
    bench_samples s, tsend;
    uint64_t total, received, late, foreign;
    int probe_answered;
    uint64_t waiting_seq, sent;
    int got_waiting, all_in;
};

static void on_ping(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    struct ctx *c = (struct ctx *)u;
    uint32_t type;
    uint64_t seq;
    int64_t t;
    if (bench_hdr_read((const unsigned char *)rb->data, rb->data_size, &type, &seq, &t) < 0)
        return;
    if (type == BENCH_MSG_FIN) {
        c->fin = 1;
        return;
    }
    if (type != BENCH_MSG_PING)
        return;
    /* Answer with the same bytes, type changed; the buffer is LCM's, so copy. */
    static unsigned char out[65536];
    size_t n = rb->data_size < sizeof out ? rb->data_size : sizeof out;
    memcpy(out, rb->data, n);
    bench_put_u32(out + 4, BENCH_MSG_PONG);
    if (lcm_publish(c->lcm, CH_PONG, out, (unsigned)n) != 0)
        fprintf(stderr, "lcm_publish failed\n");
    if (seq != PROBE_SEQ)
        c->echoed++;
}

static void on_pong(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    int64_t tr = bench_now_ns();
    struct ctx *c = (struct ctx *)u;
    uint32_t type;
    uint64_t seq;
    int64_t t;
    if (bench_hdr_read((const unsigned char *)rb->data, rb->data_size, &type, &seq, &t) < 0 ||
        type != BENCH_MSG_PONG) {
        c->foreign++;
        return;
    }
    if (seq == PROBE_SEQ) {
        c->probe_answered = 1;
        return;
    }
    if (seq >= c->total || c->tsend.v[seq] == BENCH_MISSING || c->s.v[seq] != BENCH_MISSING) {
        c->foreign++;
        return;
    }
    if (tr - c->tsend.v[seq] > c->o.timeout_ns) {
        c->late++;
        return;
    }
    c->s.v[seq] = tr - c->tsend.v[seq];
    c->received++;
    if (seq == c->waiting_seq)
        c->got_waiting = 1;
    if (c->received == c->sent)
        c->all_in = 1;
}

/* Dispatch messages until `deadline` (0 = block) or until `*done` becomes true.
 * Returns -1 on a stop signal or LCM error. */
static int handle_until(struct ctx *c, int64_t deadline, const int *done)
{
    int fd = lcm_get_fileno(c->lcm);
    while (!(done && *done)) {
        if (bench_stop_flag)
            return -1;
        struct pollfd p = {fd, POLLIN, 0};
        int r;
        if (deadline) {
            int64_t left = deadline - bench_now_ns();
            if (left <= 0)
                return 0;
            struct timespec ts = bench_ts_from_ns(left);
            r = ppoll(&p, 1, &ts, NULL);
        } else {
            r = ppoll(&p, 1, NULL, NULL);
        }
        if (r < 0 && errno != EINTR)
            return -1;
        if (r > 0 && lcm_handle(c->lcm) != 0)
            return -1;
    }
    return 0;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: lcm_pingpong --role echo|ping [--url URL] [options]\n"
            "  --url URL          LCM provider (default " DEFAULT_URL ")\n"
            "  --persist          echo: keep serving after a FIN\n"
            "  --start-wait-ms MS ping: how long to probe for the echo (default 10000)\n" BENCH_COMMON_HELP);
}

int main(int argc, char **argv)
{
    static struct ctx c;
    bench_opts_defaults(&c.o, "lcm_udpm_rtt", 8, 10000);
    c.o.rate_hz = 1000;
    const char *url = DEFAULT_URL;
    int have_role = 0;
    int64_t start_wait = 10000000000LL;
    enum { OPT_ROLE = 0x200, OPT_URL, OPT_PERSIST, OPT_START };
    static const struct option longopts[] = {BENCH_COMMON_LONGOPTS,
                                             {"role", required_argument, 0, OPT_ROLE},
                                             {"url", required_argument, 0, OPT_URL},
                                             {"persist", no_argument, 0, OPT_PERSIST},
                                             {"start-wait-ms", required_argument, 0, OPT_START},
                                             {0, 0, 0, 0}};
    static const char *const roles[] = {"echo", "ping", NULL}; /* enum role */
    int opt;
    while ((opt = bench_next_opt(argc, argv, longopts, &c.o, usage)) != -1) {
        switch (opt) {
        case OPT_ROLE:
            c.role = (enum role)bench_choice_opt(argv, optarg, roles);
            have_role = 1;
            break;
        case OPT_URL: url = optarg; break;
        case OPT_PERSIST: c.persist = 1; break;
        case OPT_START: start_wait = bench_ms_opt(argv, optarg, 1); break;
        }
    }
    if (!have_role) {
        usage(stderr);
        return BENCH_EXIT_USAGE;
    }
    c.lcm = lcm_create(url);
    if (!c.lcm) {
        fprintf(stderr, "lcm_create(%s) failed (no multicast route? see LCM's multicast setup notes)\n", url);
        return BENCH_EXIT_FAIL;
    }
    bench_rt rt = bench_rt_setup(c.o.cpu[0], c.o.prio, !c.o.no_mlock);
    bench_install_stop_handlers();

    if (c.role == R_ECHO) {
        lcm_subscribe(c.lcm, CH_PING, on_ping, &c);
        for (;;) {
            c.fin = 0;
            if (handle_until(&c, 0, &c.fin) < 0 || !c.persist)
                break;
        }
        fprintf(stderr, "{\"role\":\"echo\",\"echoed\":%" PRIu64 "}\n", c.echoed);
        lcm_destroy(c.lcm);
        return 0;
    }

    c.total = c.o.warmup + c.o.count;
    bench_samples_init(&c.s, (size_t)c.total);
    bench_samples_init(&c.tsend, (size_t)c.total);
    lcm_subscribe(c.lcm, CH_PONG, on_pong, &c);
    size_t len = BENCH_HDR_SIZE + (size_t)c.o.payload;
    unsigned char *m = (unsigned char *)calloc(1, len);
    if (!m)
        bench_die("out of memory");
    for (size_t i = BENCH_HDR_SIZE; i < len; i++)
        m[i] = (unsigned char)i;

    /* Probe until the echo answers (LCM has no connection to wait for). */
    int64_t give_up = bench_now_ns() + start_wait;
    while (!c.probe_answered && bench_now_ns() < give_up && !bench_stop_flag) {
        bench_hdr_write(m, BENCH_MSG_PING, PROBE_SEQ, bench_now_ns());
        lcm_publish(c.lcm, CH_PING, m, (unsigned)len);
        handle_until(&c, bench_now_ns() + 20000000, &c.probe_answered);
    }
    if (!c.probe_answered) {
        fprintf(stderr, "lcm ping: no answer from an echo within %" PRId64 " ms\n", start_wait / 1000000);
        return BENCH_EXIT_FAIL;
    }
    handle_until(&c, bench_now_ns() + 30000000, NULL); /* drain late probe answers */

    int64_t period = c.o.rate_hz > 0 ? (int64_t)(1e9 / c.o.rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    uint64_t sent = 0;
    for (uint64_t i = 0; i <= c.total && !bench_stop_flag; i++) {
        int64_t until;
        if (i < c.total) {
            if (period)
                bench_sleep_until(t0 + (int64_t)i * period);
            int64_t ts = bench_now_ns();
            bench_hdr_write(m, BENCH_MSG_PING, i, ts);
            c.tsend.v[i] = ts;
            if (lcm_publish(c.lcm, CH_PING, m, (unsigned)len) == 0)
                sent++;
            until = period ? t0 + (int64_t)(i + 1) * period : ts + c.o.timeout_ns;
        } else {
            if (c.received == sent)
                break;
            until = c.tsend.v[c.total - 1] + c.o.timeout_ns;
        }
        /* Back-to-back: stop waiting as soon as this message's answer is in; after
         * the last send: as soon as every answer is in. */
        c.waiting_seq = i < c.total ? i : PROBE_SEQ;
        c.got_waiting = 0;
        c.sent = sent;
        c.all_in = c.received == sent;
        if (handle_until(&c, until, i < c.total ? (period ? NULL : &c.got_waiting) : &c.all_in) < 0)
            break;
    }
    bench_hdr_write(m, BENCH_MSG_FIN, sent, bench_now_ns());
    for (int k = 0; k < 3; k++)
        lcm_publish(c.lcm, CH_PING, m, (unsigned)len);
    bench_stats st = bench_finish_samples(&c.o, &c.s, c.total);
    char extra[256];
    snprintf(extra, sizeof extra,
             ",\"program\":\"lcm_pingpong\",\"lcm_url\":\"%s\",\"sent\":%" PRIu64 ",\"late\":%" PRIu64
             ",\"foreign\":%" PRIu64,
             url, sent, c.late, c.foreign);
    bench_print_result(c.o.name, "lcm_udpm", &c.o, c.o.half ? "rtt_half" : "rtt", &st, &rt, extra);
    lcm_destroy(c.lcm);
    return c.received ? BENCH_EXIT_OK : BENCH_EXIT_FAIL;
}
