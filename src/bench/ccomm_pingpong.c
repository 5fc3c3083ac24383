/* SPDX-License-Identifier: Apache-2.0 */
/*
 * ccomm_pingpong: ccomm's on-target hand-off measured exactly like shm_floor and
 * iox_pingpong: two processes, each pinned to its own CPU, pass a value back and
 * forth through libccomm (the node's shared-memory segment, no network), back to
 * back, and the pinging side records each round trip.
 *
 *   --role echo   read --ping, write what it read to --pong
 *   --role ping   write --ping with a new sequence number, wait for it on --pong
 *   --wait spin   poll ccomm_read (a real-time loop's view: no wake-up)
 *   --wait block  sleep in ccomm_wait between reads (like the futex floor)
 * Both signals are produced and consumed on the node (a running ccommd created the
 * segment). State and event signals, any size: the first 8 bytes of the value carry
 * the sequence number, the rest is payload that is copied in and out every time.
 * Every read asks for its ccomm_info (freshness and age), as an application does.
 *
 *   --cycle-time  take the time once per loop iteration (ccomm_set_time), as a control
 *                 loop does, instead of ccomm reading the clock in every read and write:
 *                 the ping side once per round trip (its send time), the echo once per
 *                 poll (a value is then stamped with the poll that saw its request)
 */
#include "bench_common.h"

#include "ccomm/ccomm.h"

#define FIN_SEQ UINT64_MAX
#define PROBE_SEQ (UINT64_MAX - 1)
#define MAX_VALUE 1024

enum role { R_ECHO, R_PING };
enum waitmode { W_SPIN, W_BLOCK };

struct side {
    ccomm_client *c;
    ccomm_signal in, out;
    size_t len;
    enum waitmode wait;
    int event;
    int cycle_time; /* echo: ccomm_set_time before every poll */
};

static uint64_t seq_of(const unsigned char *v)
{
    uint64_t s;
    memcpy(&s, v, sizeof s);
    return s;
}

/* Reads `in` until its value carries a sequence other than `last` (echo) or equal to
 * `want` (ping; want != 0). Returns the sequence seen, 0 on timeout or stop. */
static uint64_t await(struct side *s, unsigned char *v, uint64_t last, uint64_t want, int64_t deadline)
{
    unsigned spins = 0;
    for (;;) {
        ccomm_info info;
        if (s->cycle_time && !want)
            ccomm_set_time(s->c, bench_now_ns());
        int r = ccomm_read(s->c, s->in, v, s->len, &info);
        if (r == CCOMM_FRESH || r == CCOMM_STALE) {
            uint64_t q = seq_of(v);
            if (want ? q == want : q != last)
                return q;
            if (s->event)
                continue; /* an older event still queued: take the next one at once */
        } else if (r < 0) {
            bench_die("ccomm_read: %s", ccomm_strerror(r));
        }
        if (bench_stop_flag)
            return 0;
        if (s->wait == W_BLOCK) {
            ccomm_wait(s->c, 100);
            if (deadline && bench_now_ns() > deadline)
                return 0;
            continue;
        }
        bench_cpu_relax();
        if ((++spins & 1023u) == 0 && deadline && bench_now_ns() > deadline)
            return 0;
    }
}

static void put(struct side *s, unsigned char *v, uint64_t seq)
{
    memcpy(v, &seq, sizeof seq);
    int r = ccomm_write(s->c, s->out, v, s->len);
    if (r != 0)
        bench_die("ccomm_write: %s", ccomm_strerror(r));
}

static ccomm_signal find(ccomm_client *c, const char *name, ccomm_signal_desc *d)
{
    ccomm_signal id = ccomm_find(c, name);
    if (id < 0 || ccomm_describe(c, id, d) != 0)
        bench_die("signal %s: %s", name, ccomm_strerror(id < 0 ? id : CCOMM_E_NOENT));
    if (d->value_bytes < 8 || d->value_bytes > MAX_VALUE)
        bench_die("signal %s: value of %u bytes (need 8..%d)", name, d->value_bytes, MAX_VALUE);
    return id;
}

/* What one reading of ccomm's clock costs here (ns): the price of a per-call time stamp. */
static double clock_cost_ns(void)
{
    const int n = 200000;
    volatile int64_t sink = 0;
    int64_t t0 = bench_now_ns();
    for (int i = 0; i < n; i++)
        sink = ccomm_now();
    (void)sink;
    return (double)(bench_now_ns() - t0) / n;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: ccomm_pingpong --role echo|ping --ping SIG --pong SIG [options]\n"
            "  --node NAME        node to attach to (default $CCOMM_NODE / hostname)\n"
            "  --wait MODE        spin (default) or block\n"
            "  --cycle-time       one clock reading per loop iteration (ccomm_set_time)\n"
            "  --start-wait-ms MS ping: how long to wait for the echo (default 10000)\n" BENCH_COMMON_HELP
            "The payload is the signals' size (--payload is checked against it).\n"
            "Needs a running ccommd for the node, both signals produced and consumed there.\n");
}

int main(int argc, char **argv)
{
    bench_opts o;
    bench_opts_defaults(&o, NULL, 8, 100000);
    o.warmup = 1000;
    enum role role = R_PING;
    int have_role = 0;
    const char *node = NULL, *ping_name = NULL, *pong_name = NULL;
    int64_t start_wait = 10000000000LL;
    enum waitmode wait = W_SPIN;
    int cycle_time = 0;
    enum { OPT_ROLE = 0x200, OPT_WAIT, OPT_NODE, OPT_PING, OPT_PONG, OPT_START, OPT_CYCLE, OPT_HELP };
    static const struct option longopts[] = {BENCH_COMMON_LONGOPTS,
                                             {"role", required_argument, 0, OPT_ROLE},
                                             {"wait", required_argument, 0, OPT_WAIT},
                                             {"node", required_argument, 0, OPT_NODE},
                                             {"ping", required_argument, 0, OPT_PING},
                                             {"pong", required_argument, 0, OPT_PONG},
                                             {"start-wait-ms", required_argument, 0, OPT_START},
                                             {"cycle-time", no_argument, 0, OPT_CYCLE},
                                             {"help", no_argument, 0, OPT_HELP},
                                             {0, 0, 0, 0}};
    int opt;
    uint64_t u;
    while ((opt = getopt_long(argc, argv, "", longopts, NULL)) != -1) {
        int r = bench_common_opt(&o, opt, optarg);
        if (r == 1)
            continue;
        int bad = r < 0;
        switch (opt) {
        case OPT_ROLE:
            have_role = 1;
            if (!strcmp(optarg, "echo"))
                role = R_ECHO;
            else if (!strcmp(optarg, "ping"))
                role = R_PING;
            else
                bad = 1;
            break;
        case OPT_WAIT:
            if (!strcmp(optarg, "spin"))
                wait = W_SPIN;
            else if (!strcmp(optarg, "block"))
                wait = W_BLOCK;
            else
                bad = 1;
            break;
        case OPT_NODE: node = optarg; break;
        case OPT_PING: ping_name = optarg; break;
        case OPT_PONG: pong_name = optarg; break;
        case OPT_START:
            bad = bench_parse_u64(optarg, &u) != 0;
            start_wait = (int64_t)u * 1000000LL;
            break;
        case OPT_CYCLE: cycle_time = 1; break;
        case OPT_HELP: usage(stdout); return 0;
        default:
            if (!bad) {
                usage(stderr);
                return BENCH_EXIT_USAGE;
            }
        }
        if (bad) {
            fprintf(stderr, "bad value for option: %s\n", optarg ? optarg : "");
            return BENCH_EXIT_USAGE;
        }
    }
    if (!have_role || !ping_name || !pong_name || optind != argc) {
        usage(stderr);
        return BENCH_EXIT_USAGE;
    }

    struct side s;
    memset(&s, 0, sizeof s);
    s.wait = wait;
    s.cycle_time = cycle_time;
    int r = ccomm_open(node, 0, &s.c);
    if (r != 0) {
        fprintf(stderr, "ccomm_open: %s\n", ccomm_strerror(r));
        return r == CCOMM_E_NOENT ? BENCH_EXIT_SKIP : BENCH_EXIT_FAIL;
    }
    ccomm_signal_desc dp, dq;
    ccomm_signal ping = find(s.c, ping_name, &dp), pong = find(s.c, pong_name, &dq);
    if (dp.value_bytes != dq.value_bytes || dp.is_event != dq.is_event)
        bench_die("--ping and --pong must have the same size and kind");
    s.len = dp.value_bytes;
    s.event = dp.is_event;
    if (o.payload != (long)s.len)
        bench_die("--payload %ld but the signals carry %zu bytes", o.payload, s.len);
    s.in = role == R_ECHO ? ping : pong;
    s.out = role == R_ECHO ? pong : ping;

    char defname[48];
    snprintf(defname, sizeof defname, "ccomm_%s_%s%s", s.event ? "event" : "state", wait == W_SPIN ? "spin" : "block",
             cycle_time ? "_cycle" : "");
    if (!o.name)
        o.name = defname;
    bench_rt rt = bench_rt_setup(o.cpu[0], o.prio, !o.no_mlock);
    bench_install_stop_handlers();
    static unsigned char v[MAX_VALUE], in[MAX_VALUE];
    for (size_t i = 8; i < s.len; i++)
        v[i] = (unsigned char)i;

    if (role == R_ECHO) {
        /* A state keeps its last value: remember it so an old run's value is no request. */
        ccomm_info info;
        uint64_t last = 0, echoed = 0;
        if (!s.event && ccomm_read(s.c, s.in, in, s.len, &info) == CCOMM_FRESH)
            last = seq_of(in);
        for (;;) {
            uint64_t q = await(&s, in, last, 0, 0);
            if (!q || q == FIN_SEQ)
                break;
            last = q;
            memcpy(v + 8, in + 8, s.len - 8);
            put(&s, v, q);
            echoed++;
        }
        fprintf(stderr, "{\"role\":\"echo\",\"echoed\":%" PRIu64 "}\n", echoed);
        ccomm_close(s.c);
        return BENCH_EXIT_OK;
    }

    uint64_t total = o.warmup + o.count;
    bench_samples smp;
    bench_samples_init(&smp, (size_t)total);
    /* Sequence numbers start from a per-run base so an echo never mistakes a value of
     * an earlier run for a request. */
    uint64_t base = ((uint64_t)bench_now_ns() & 0xffffffffull) << 24;
    int64_t give_up = bench_now_ns() + start_wait;
    int ready = 0;
    while (!ready && bench_now_ns() < give_up && !bench_stop_flag) {
        put(&s, v, PROBE_SEQ - (uint64_t)(bench_now_ns() & 0xffff));
        ready = await(&s, in, 0, seq_of(v), bench_now_ns() + 20000000) != 0;
    }
    if (!ready) {
        fprintf(stderr, "ccomm ping: no echo within %" PRId64 " ms\n", start_wait / 1000000);
        ccomm_close(s.c);
        return BENCH_EXIT_FAIL;
    }
    int64_t period = o.rate_hz > 0 ? (int64_t)(1e9 / o.rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    uint64_t consecutive_lost = 0, received = 0;
    for (uint64_t i = 0; i < total && !bench_stop_flag; i++) {
        if (period)
            bench_sleep_until(t0 + (int64_t)i * period);
        uint64_t q = base + i + 1;
        int64_t t1 = bench_now_ns();
        if (cycle_time)
            ccomm_set_time(s.c, t1);
        put(&s, v, q);
        if (await(&s, in, 0, q, t1 + o.timeout_ns)) {
            smp.v[i] = bench_now_ns() - t1;
            received++;
            consecutive_lost = 0;
        } else if (++consecutive_lost >= 3) {
            fprintf(stderr, "no answer for 3 requests in a row; giving up\n");
            break;
        }
    }
    put(&s, v, FIN_SEQ);
    bench_stats st = bench_finish_samples(&o, &smp, total);
    char extra[240];
    snprintf(extra, sizeof extra,
             ",\"program\":\"ccomm_pingpong\",\"wait\":\"%s\",\"signal_kind\":\"%s\",\"clock\":\"%s\""
             ",\"clock_read_ns\":%.1f",
             wait == W_SPIN ? "spin" : "block", s.event ? "event" : "state", cycle_time ? "cycle" : "per_call",
             clock_cost_ns());
    bench_print_result(o.name, "shm", &o, o.half ? "rtt_half" : "rtt", &st, &rt, extra);
    ccomm_close(s.c);
    return (!received || bench_stop_flag) ? BENCH_EXIT_FAIL : BENCH_EXIT_OK;
}
