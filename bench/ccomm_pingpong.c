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
 *   --floor-shm NAME  (spin only) interleave the floor: blocks of --block round trips
 *                 through a bare cache line in shared memory object NAME (the ping side
 *                 creates it; shm_floor's exchange) alternate with blocks through ccomm,
 *                 between the same two processes on the same CPUs. The result adds the
 *                 floor's p50 and the median over block pairs of ccomm's block p50 /
 *                 the floor's block p50: on a shared host, whose placement of the two
 *                 virtual CPUs changes from one second to the next, only a ratio taken
 *                 milliseconds apart compares like with like.
 */
#include "bench_common.h"

#include <fcntl.h>
#include <stdatomic.h>
#include <sys/stat.h>

#include "ccomm/ccomm.h"

#define FIN_SEQ UINT64_MAX
#define PROBE_SEQ (UINT64_MAX - 1)
#define MAX_VALUE 1024
#define FLOOR_STOP 0xFFFFFFFFu /* odd, never a real request */

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

/* The floor's cache line: odd turn = request 2i+1, even = its answer; payload after it. */
struct floor_line {
    _Alignas(64) _Atomic uint32_t turn;
    unsigned char data[MAX_VALUE];
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

/* Echo side of one floor exchange: 1 answered, 0 stop. */
static int floor_answer(struct floor_line *f, uint32_t *last, size_t len)
{
    unsigned char local[MAX_VALUE];
    for (;;) {
        uint32_t t = atomic_load_explicit(&f->turn, memory_order_acquire);
        if (t == FLOOR_STOP || bench_stop_flag)
            return 0;
        if ((t & 1u) && t != *last) {
            *last = t;
            memcpy(local, f->data, len);
            memcpy(f->data, local, len);
            atomic_store_explicit(&f->turn, t + 1, memory_order_release);
            return 1;
        }
        bench_cpu_relax();
    }
}

/* Ping side of one floor exchange: the round trip in ns, or -1 after `timeout_ns`. */
static int64_t floor_exchange(struct floor_line *f, uint32_t req, const unsigned char *out, size_t len,
                              int64_t timeout_ns)
{
    unsigned spins = 0;
    int64_t t1 = bench_now_ns();
    memcpy(f->data, out, len);
    atomic_store_explicit(&f->turn, req, memory_order_release);
    while (atomic_load_explicit(&f->turn, memory_order_acquire) != req + 1) {
        bench_cpu_relax();
        if ((++spins & 1023u) == 0 && bench_now_ns() - t1 > timeout_ns)
            return -1;
    }
    return bench_now_ns() - t1;
}

/* Either side may come first: both create the object if needed. Use a fresh name per
 * run (it must start zeroed); the ping side removes it at the end. */
static struct floor_line *floor_map(const char *name)
{
    return (struct floor_line *)bench_shm_map(name, sizeof(struct floor_line));
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

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Median of v[0..n) (sorts a copy into tmp). */
static int64_t median_of(const int64_t *v, size_t n, int64_t *tmp)
{
    memcpy(tmp, v, n * sizeof *v);
    qsort(tmp, n, sizeof *tmp, cmp_i64);
    return n ? tmp[n / 2] : 0;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: ccomm_pingpong --role echo|ping --ping SIG --pong SIG [options]\n"
            "  --node NAME        node to attach to (default $CCOMM_NODE / hostname)\n"
            "  --wait MODE        spin (default) or block\n"
            "  --cycle-time       one clock reading per loop iteration (ccomm_set_time)\n"
            "  --floor-shm NAME   spin: interleave blocks through a bare shared cache line (both sides;\n"
            "                     a new name per run, e.g. /ccpp-$$)\n"
            "  --block N          round trips per interleaved block (default 1000)\n"
            "  --start-wait-ms MS ping: how long to wait for the echo (default 10000)\n" BENCH_COMMON_HELP
            "The payload is the signals' size (--payload is checked against it).\n"
            "Needs a running ccommd for the node, both signals produced and consumed there.\n");
}

struct run {
    struct side s;
    struct floor_line *floor; /* NULL: ccomm only */
    uint64_t block;
};

/* Is exchange i (from 0) a floor exchange? Blocks alternate, floor first. */
static int is_floor(const struct run *r, uint64_t i)
{
    return r->floor && (i / r->block) % 2 == 0;
}

static int echo_main(struct run *r)
{
    struct side *s = &r->s;
    static unsigned char v[MAX_VALUE], in[MAX_VALUE];
    ccomm_info info;
    uint64_t last = 0, echoed = 0;
    uint32_t floor_last = 0;
    /* A state keeps its last value: remember it so an old run's value is no request. */
    if (!s->event && ccomm_read(s->c, s->in, in, s->len, &info) == CCOMM_FRESH)
        last = seq_of(in);
    /* Probes (ccomm) until the ping side starts its schedule. With a floor, the
     * schedule begins with a floor request: watch both until it comes. */
    for (;;) {
        if (r->floor) {
            uint32_t t = atomic_load_explicit(&r->floor->turn, memory_order_acquire);
            if (t == FLOOR_STOP)
                return BENCH_EXIT_OK;
            if (t & 1u)
                break;
        }
        int rr = ccomm_read(s->c, s->in, in, s->len, &info);
        if ((rr == CCOMM_FRESH || rr == CCOMM_STALE) && seq_of(in) != last) {
            last = seq_of(in);
            if (last == FIN_SEQ)
                return BENCH_EXIT_OK;
            memcpy(v + 8, in + 8, s->len - 8);
            put(s, v, last);
            if (!r->floor && last != PROBE_SEQ && last < PROBE_SEQ - 0x10000)
                break; /* ccomm only: the first real request; answered, go on below */
            continue;
        }
        if (bench_stop_flag)
            return BENCH_EXIT_OK;
        bench_cpu_relax();
    }
    for (uint64_t i = r->floor ? 0 : 1;; i++) {
        if (is_floor(r, i)) {
            if (!floor_answer(r->floor, &floor_last, s->len))
                break;
            continue;
        }
        uint64_t q = await(s, in, last, 0, 0);
        if (!q || q == FIN_SEQ)
            break;
        last = q;
        memcpy(v + 8, in + 8, s->len - 8);
        put(s, v, q);
        echoed++;
    }
    fprintf(stderr, "{\"role\":\"echo\",\"echoed\":%" PRIu64 "}\n", echoed);
    return BENCH_EXIT_OK;
}

int main(int argc, char **argv)
{
    bench_opts o;
    bench_opts_defaults(&o, NULL, 8, 100000);
    o.warmup = 1000;
    enum role role = R_PING;
    int have_role = 0;
    const char *node = NULL, *ping_name = NULL, *pong_name = NULL, *floor_name = NULL;
    int64_t start_wait = 10000000000LL;
    enum waitmode wait = W_SPIN;
    int cycle_time = 0;
    uint64_t block = 1000;
    enum { OPT_ROLE = 0x200, OPT_WAIT, OPT_NODE, OPT_PING, OPT_PONG, OPT_START, OPT_CYCLE, OPT_FLOOR, OPT_BLOCK };
    static const struct option longopts[] = {BENCH_COMMON_LONGOPTS,
                                             {"role", required_argument, 0, OPT_ROLE},
                                             {"wait", required_argument, 0, OPT_WAIT},
                                             {"node", required_argument, 0, OPT_NODE},
                                             {"ping", required_argument, 0, OPT_PING},
                                             {"pong", required_argument, 0, OPT_PONG},
                                             {"start-wait-ms", required_argument, 0, OPT_START},
                                             {"cycle-time", no_argument, 0, OPT_CYCLE},
                                             {"floor-shm", required_argument, 0, OPT_FLOOR},
                                             {"block", required_argument, 0, OPT_BLOCK},
                                             {0, 0, 0, 0}};
    static const char *const roles[] = {"echo", "ping", NULL};  /* enum role */
    static const char *const waits[] = {"spin", "block", NULL}; /* enum waitmode */
    int opt;
    while ((opt = bench_next_opt(argc, argv, longopts, &o, usage)) != -1) {
        switch (opt) {
        case OPT_ROLE:
            role = (enum role)bench_choice_opt(argv, optarg, roles);
            have_role = 1;
            break;
        case OPT_WAIT: wait = (enum waitmode)bench_choice_opt(argv, optarg, waits); break;
        case OPT_NODE: node = optarg; break;
        case OPT_PING: ping_name = optarg; break;
        case OPT_PONG: pong_name = optarg; break;
        case OPT_START: start_wait = bench_ms_opt(argv, optarg, 1); break;
        case OPT_CYCLE: cycle_time = 1; break;
        case OPT_FLOOR: floor_name = optarg; break;
        case OPT_BLOCK:
            if (bench_parse_u64(optarg, &block) || block == 0)
                bench_bad_value(argv, optarg);
            break;
        }
    }
    if (!have_role || !ping_name || !pong_name) {
        usage(stderr);
        return BENCH_EXIT_USAGE;
    }
    if (floor_name && wait != W_SPIN) {
        fprintf(stderr, "--floor-shm needs --wait spin (the floor busy-reads)\n");
        return BENCH_EXIT_USAGE;
    }

    struct run run;
    memset(&run, 0, sizeof run);
    struct side *s = &run.s;
    s->wait = wait;
    s->cycle_time = cycle_time;
    run.block = block;
    int r = ccomm_open(node, 0, &s->c);
    if (r != 0) {
        fprintf(stderr, "ccomm_open: %s\n", ccomm_strerror(r));
        return r == CCOMM_E_NOENT ? BENCH_EXIT_SKIP : BENCH_EXIT_FAIL;
    }
    ccomm_signal_desc dp, dq;
    ccomm_signal ping = find(s->c, ping_name, &dp), pong = find(s->c, pong_name, &dq);
    if (dp.value_bytes != dq.value_bytes || dp.is_event != dq.is_event)
        bench_die("--ping and --pong must have the same size and kind");
    s->len = dp.value_bytes;
    s->event = dp.is_event;
    if (o.payload != (long)s->len)
        bench_die("--payload %ld but the signals carry %zu bytes", o.payload, s->len);
    s->in = role == R_ECHO ? ping : pong;
    s->out = role == R_ECHO ? pong : ping;
    if (floor_name)
        run.floor = floor_map(floor_name);

    char defname[48];
    snprintf(defname, sizeof defname, "ccomm_%s_%s%s", s->event ? "event" : "state", wait == W_SPIN ? "spin" : "block",
             cycle_time ? "_cycle" : "");
    if (!o.name)
        o.name = defname;
    bench_rt rt = bench_rt_setup(o.cpu[0], o.prio, !o.no_mlock);
    bench_install_stop_handlers();
    if (role == R_ECHO) {
        int rc = echo_main(&run);
        ccomm_close(s->c);
        return rc;
    }

    static unsigned char v[MAX_VALUE], in[MAX_VALUE];
    for (size_t i = 8; i < s->len; i++)
        v[i] = (unsigned char)i;
    /* With a floor: total ccomm and total floor exchanges, whole blocks of each. */
    uint64_t total = o.warmup + o.count;
    if (run.floor)
        total = (total + block - 1) / block * block;
    bench_samples smp, fsmp;
    bench_samples_init(&smp, (size_t)total);
    bench_samples_init(&fsmp, run.floor ? (size_t)total : 1);
    /* Sequence numbers start from a per-run base so an echo never mistakes a value of
     * an earlier run for a request. */
    uint64_t base = ((uint64_t)bench_now_ns() & 0xffffffffull) << 24;
    int64_t give_up = bench_now_ns() + start_wait;
    int ready = 0;
    while (!ready && bench_now_ns() < give_up && !bench_stop_flag) {
        put(s, v, PROBE_SEQ - (uint64_t)(bench_now_ns() & 0xffff));
        ready = await(s, in, 0, seq_of(v), bench_now_ns() + 20000000) != 0;
    }
    if (!ready) {
        fprintf(stderr, "ccomm ping: no echo within %" PRId64 " ms\n", start_wait / 1000000);
        if (run.floor)
            atomic_store_explicit(&run.floor->turn, FLOOR_STOP, memory_order_release);
        ccomm_close(s->c);
        return BENCH_EXIT_FAIL;
    }
    int64_t period = o.rate_hz > 0 ? (int64_t)(1e9 / o.rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    uint64_t consecutive_lost = 0, received = 0, nc = 0, nf = 0;
    uint32_t req = 1;
    for (uint64_t i = 0; (nc < total || (run.floor && nf < total)) && !bench_stop_flag; i++) {
        if (period)
            bench_sleep_until(t0 + (int64_t)i * period);
        int64_t rtt;
        if (is_floor(&run, i)) {
            rtt = floor_exchange(run.floor, req, v, s->len, o.timeout_ns);
            req += 2;
            if (rtt >= 0)
                fsmp.v[nf] = rtt;
            nf++;
        } else {
            uint64_t q = base + nc + 1;
            int64_t t1 = bench_now_ns();
            if (cycle_time)
                ccomm_set_time(s->c, t1);
            put(s, v, q);
            rtt = await(s, in, 0, q, t1 + o.timeout_ns) ? bench_now_ns() - t1 : -1;
            if (rtt >= 0) {
                smp.v[nc] = rtt;
                received++;
            }
            nc++;
        }
        if (rtt >= 0) {
            consecutive_lost = 0;
        } else if (++consecutive_lost >= 3) {
            fprintf(stderr, "no answer for 3 requests in a row; giving up\n");
            break;
        }
    }
    put(s, v, FIN_SEQ);
    if (run.floor)
        atomic_store_explicit(&run.floor->turn, FLOOR_STOP, memory_order_release);

    /* Block pairs: block k of ccomm against block k of the floor, measured just before. */
    char pairs[160] = "";
    if (run.floor) {
        if (o.half)
            for (size_t i = 0; i < fsmp.cap; i++)
                if (fsmp.v[i] != BENCH_MISSING)
                    fsmp.v[i] /= 2;
    }
    bench_stats st = bench_finish_samples(&o, &smp, total);
    if (run.floor) {
        bench_stats fst = bench_summarize(&fsmp, (size_t)o.warmup, (size_t)total);
        uint64_t nblocks = total / block, first = (o.warmup + block - 1) / block, used = 0;
        int64_t *tmp = malloc(block * sizeof *tmp);
        double *ratios = malloc((nblocks ? nblocks : 1) * sizeof *ratios);
        if (!tmp || !ratios)
            bench_die("out of memory");
        for (uint64_t k = first; k < nblocks; k++) {
            int64_t mc = median_of(smp.v + k * block, block, tmp), mf = median_of(fsmp.v + k * block, block, tmp);
            if (mc > 0 && mf > 0)
                ratios[used++] = (double)mc / (double)mf;
        }
        for (uint64_t a = 1; a < used; a++) /* insertion sort: a few hundred at most */
            for (uint64_t b = a; b > 0 && ratios[b - 1] > ratios[b]; b--) {
                double x = ratios[b];
                ratios[b] = ratios[b - 1];
                ratios[b - 1] = x;
            }
        double med = used ? (used % 2 ? ratios[used / 2] : (ratios[used / 2 - 1] + ratios[used / 2]) / 2) : 0;
        snprintf(pairs, sizeof pairs,
                 ",\"floor_p50_ns\":%" PRId64 ",\"floor_count\":%" PRIu64 ",\"block\":%" PRIu64
                 ",\"block_pairs\":%" PRIu64 ",\"paired_ratio\":%.3f",
                 fst.p50, fst.count, block, used, med);
        free(tmp);
        free(ratios);
    }
    char extra[480];
    snprintf(extra, sizeof extra,
             ",\"program\":\"ccomm_pingpong\",\"wait\":\"%s\",\"signal_kind\":\"%s\",\"clock\":\"%s\""
             ",\"clock_read_ns\":%.1f%s",
             wait == W_SPIN ? "spin" : "block", s->event ? "event" : "state", cycle_time ? "cycle" : "per_call",
             clock_cost_ns(), pairs);
    bench_print_result(o.name, "shm", &o, o.half ? "rtt_half" : "rtt", &st, &rt, extra);
    ccomm_close(s->c);
    if (run.floor && role == R_PING && floor_name)
        bench_shm_remove(floor_name);
    return (!received || bench_stop_flag) ? BENCH_EXIT_FAIL : BENCH_EXIT_OK;
}
