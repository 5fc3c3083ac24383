/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Shared helpers of the floor and peer latency programs: monotonic timestamps,
 * a preallocated sample buffer, summary statistics, the one-line JSON result,
 * raw sample dumps, the real-time set-up (CPU pinning, SCHED_FIFO, mlockall) and a
 * shared-memory object.
 *
 * The bench's own platform layer: the one place its C programs make the OS calls that
 * ccomm's code makes only in src/common/platform/ (shm_open, mlockall,
 * sched_setscheduler, clock_nanosleep). A floor or peer program links nothing of ccomm
 * (a floor measures the OS alone, a peer runs as its own users run it); the programs
 * that do link libccomm (ccomm_pingpong's ccomm side, manyboards_app) set up through
 * ccomm_realtime_setup like any application. The Rust peers' counterpart is
 * peers/common/src/lib.rs.
 *
 * Header-only and libc-only on purpose: net_floor is cross-compiled for 32-bit ARM
 * with nothing but `cc -O2 net_floor.c` and this header beside it.
 */
#ifndef CCOMM_BENCH_COMMON_H
#define CCOMM_BENCH_COMMON_H

#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif

#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <inttypes.h>
#include <limits.h>
#include <sched.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#define BENCH_NS_PER_S 1000000000LL

/* Exit codes shared with the driver: 0 ok, 1 runtime failure, 2 usage, 4 skipped
 * (missing privilege or facility, not a failure of the measured thing). */
#define BENCH_EXIT_OK 0
#define BENCH_EXIT_FAIL 1
#define BENCH_EXIT_USAGE 2
#define BENCH_EXIT_SKIP 4

static inline int64_t bench_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * BENCH_NS_PER_S + (int64_t)ts.tv_nsec;
}

static inline struct timespec bench_ts_from_ns(int64_t ns)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(ns / BENCH_NS_PER_S);
    ts.tv_nsec = (long)(ns % BENCH_NS_PER_S);
    return ts;
}

/* Sleep until an absolute CLOCK_MONOTONIC time, as a periodic control loop does
 * (no drift accumulates, unlike relative sleeps). */
static inline void bench_sleep_until(int64_t abs_ns)
{
    struct timespec ts = bench_ts_from_ns(abs_ns);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
    }
}

static inline void bench_cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__) || (defined(__arm__) && defined(__ARM_ARCH) && __ARM_ARCH >= 7)
    __asm__ __volatile__("yield" ::: "memory");
#else
    __asm__ __volatile__("" ::: "memory");
#endif
}

static inline void bench_die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    exit(BENCH_EXIT_FAIL);
}

/* ---- little-endian field access (wire headers; safe for unaligned ARM) ---- */
static inline void bench_put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}
static inline uint32_t bench_get_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline void bench_put_u64(unsigned char *p, uint64_t v)
{
    bench_put_u32(p, (uint32_t)v);
    bench_put_u32(p + 4, (uint32_t)(v >> 32));
}
static inline uint64_t bench_get_u64(const unsigned char *p)
{
    return (uint64_t)bench_get_u32(p) | ((uint64_t)bench_get_u32(p + 4) << 32);
}

/*
 * Bench message header carried in front of the application payload by every
 * message-passing program (net_floor, lcm_pingpong, iox_pingpong), so payload_bytes
 * always means "application bytes" (8 = one double) and the header is overhead
 * the same for all of them.
 */
#define BENCH_MSG_MAGIC 0x43434231u /* "CCB1" */
enum { BENCH_MSG_PING = 1, BENCH_MSG_PONG = 2, BENCH_MSG_DATA = 3, BENCH_MSG_FIN = 4 };
#define BENCH_HDR_SIZE 24u /* magic u32, type u32, seq u64, send time ns u64 */

static inline void bench_hdr_write(unsigned char *p, uint32_t type, uint64_t seq, int64_t t_ns)
{
    bench_put_u32(p, BENCH_MSG_MAGIC);
    bench_put_u32(p + 4, type);
    bench_put_u64(p + 8, seq);
    bench_put_u64(p + 16, (uint64_t)t_ns);
}
static inline int bench_hdr_read(const unsigned char *p, size_t len, uint32_t *type, uint64_t *seq, int64_t *t_ns)
{
    if (len < BENCH_HDR_SIZE || bench_get_u32(p) != BENCH_MSG_MAGIC)
        return -1;
    *type = bench_get_u32(p + 4);
    *seq = bench_get_u64(p + 8);
    *t_ns = (int64_t)bench_get_u64(p + 16);
    return 0;
}

/* ---- samples ---- */

/* One slot per message, indexed by sequence number; BENCH_MISSING marks a message
 * that got no reply in time. Allocated and touched before the run so the hot loop
 * never faults a page in. */
#define BENCH_MISSING INT64_MIN

typedef struct {
    int64_t *v;
    size_t cap;
} bench_samples;

static inline void bench_samples_init(bench_samples *s, size_t cap)
{
    s->cap = cap ? cap : 1;
    s->v = (int64_t *)malloc(s->cap * sizeof(int64_t));
    if (!s->v)
        bench_die("out of memory for %zu samples", s->cap);
    for (size_t i = 0; i < s->cap; i++)
        s->v[i] = BENCH_MISSING;
}

typedef struct {
    int64_t min, p50, p90, p99, p999, max;
    double mean;
    uint64_t count, lost;
} bench_stats;

static inline int bench_cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Nearest-rank percentile of a sorted array. */
static inline int64_t bench_pct(const int64_t *sorted, size_t n, double q)
{
    if (n == 0)
        return 0;
    double r = q * (double)n;
    size_t k = (size_t)r;
    if ((double)k < r)
        k++;
    if (k < 1)
        k = 1;
    if (k > n)
        k = n;
    return sorted[k - 1];
}

/* Summary over slots [from, to): missing slots count as lost. Works on a copy so
 * the slots stay in sequence order for the raw dump. */
static inline bench_stats bench_summarize(const bench_samples *s, size_t from, size_t to)
{
    bench_stats st;
    memset(&st, 0, sizeof st);
    if (to > s->cap)
        to = s->cap;
    if (from > to)
        from = to;
    int64_t *tmp = (int64_t *)malloc((to - from + 1) * sizeof(int64_t));
    if (!tmp)
        bench_die("out of memory");
    size_t n = 0;
    long double sum = 0;
    for (size_t i = from; i < to; i++) {
        if (s->v[i] == BENCH_MISSING) {
            st.lost++;
            continue;
        }
        tmp[n++] = s->v[i];
        sum += s->v[i];
    }
    st.count = n;
    if (n) {
        qsort(tmp, n, sizeof(int64_t), bench_cmp_i64);
        st.min = tmp[0];
        st.max = tmp[n - 1];
        st.p50 = bench_pct(tmp, n, 0.50);
        st.p90 = bench_pct(tmp, n, 0.90);
        st.p99 = bench_pct(tmp, n, 0.99);
        st.p999 = bench_pct(tmp, n, 0.999);
        st.mean = (double)(sum / (long double)n);
    }
    free(tmp);
    return st;
}

/* Raw samples, "seq<TAB>ns" per line (lost ones as "seq<TAB>-1"), for plots. */
static inline int bench_dump(const char *path, const bench_samples *s, size_t from, size_t to)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
        return -1;
    }
    if (to > s->cap)
        to = s->cap;
    for (size_t i = from; i < to; i++) {
        if (s->v[i] == BENCH_MISSING)
            fprintf(f, "%zu\t-1\n", i);
        else
            fprintf(f, "%zu\t%" PRId64 "\n", i, s->v[i]);
    }
    return fclose(f);
}

/* ---- common options ---- */

typedef struct {
    const char *name;      /* result name; defaults per program */
    const char *dump;      /* raw sample file or NULL */
    const char *cpu_list;  /* "A" or "A,B": pin (first = this/pinging side, second = peer side) */
    int cpu[2];
    int prio;              /* SCHED_FIFO priority, 0 = leave the policy alone */
    long payload;          /* application payload bytes */
    double rate_hz;        /* 0 = back-to-back */
    uint64_t count;        /* measured messages (after warm-up) */
    uint64_t warmup;       /* messages exchanged but not measured */
    int64_t timeout_ns;    /* reply deadline per message */
    int half;              /* report RTT/2 instead of RTT */
    int no_mlock;
} bench_opts;

/* Long option codes for the shared options; programs start their own at 0x200. */
enum {
    BO_NAME = 0x100, BO_DUMP, BO_CPU, BO_PRIO, BO_PAYLOAD, BO_RATE, BO_COUNT, BO_WARMUP,
    BO_TIMEOUT, BO_HALF, BO_NO_MLOCK, BO_HELP
};

#define BENCH_COMMON_LONGOPTS                                                           \
    {"name", required_argument, 0, BO_NAME}, {"dump", required_argument, 0, BO_DUMP},     \
    {"cpu", required_argument, 0, BO_CPU}, {"prio", required_argument, 0, BO_PRIO},        \
    {"payload", required_argument, 0, BO_PAYLOAD}, {"rate", required_argument, 0, BO_RATE}, \
    {"count", required_argument, 0, BO_COUNT}, {"warmup", required_argument, 0, BO_WARMUP}, \
    {"timeout-ms", required_argument, 0, BO_TIMEOUT}, {"half", no_argument, 0, BO_HALF},   \
    {"no-mlock", no_argument, 0, BO_NO_MLOCK}, {"help", no_argument, 0, BO_HELP}

#define BENCH_COMMON_HELP                                                                  \
    "  --name NAME        result name in the JSON line\n"                                  \
    "  --payload BYTES    application payload bytes (8 = 1 double, 72 = 9, 288 = 36)\n"    \
    "  --rate HZ          periodic sends with absolute sleeps; 0 = back-to-back\n"         \
    "  --count N          measured messages; --warmup N more are sent first, unmeasured\n" \
    "  --timeout-ms MS    reply deadline per message (late = lost)\n"                      \
    "  --half             report RTT/2 (one-way estimate) instead of RTT\n"                \
    "  --cpu A[,B]        pin this side to CPU A (and the peer side to B where it applies)\n" \
    "  --prio P           SCHED_FIFO priority P (needs privilege; 0 = leave as is)\n"      \
    "  --no-mlock         do not mlockall (default: lock when permitted)\n"                \
    "  --dump FILE        write raw samples (seq<TAB>ns, -1 = lost) to FILE\n"

static inline void bench_opts_defaults(bench_opts *o, const char *name, long payload, uint64_t count)
{
    memset(o, 0, sizeof *o);
    o->name = name;
    o->cpu[0] = o->cpu[1] = -1;
    o->payload = payload;
    o->count = count;
    o->warmup = 100;
    o->timeout_ns = 1000LL * 1000 * 1000;
}

/* The index of `arg` in the NULL-terminated `words`, or -1: option values that name one
 * of a few modes (e.g. --role echo|ping), in the order of the program's enum. */
static inline int bench_choice(const char *arg, const char *const *words)
{
    for (int i = 0; words[i]; i++)
        if (!strcmp(arg, words[i]))
            return i;
    return -1;
}

static inline int bench_parse_u64(const char *s, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 0);
    if (errno || end == s || *end || s[0] == '-')
        return -1;
    *out = (uint64_t)v;
    return 0;
}

/* Returns 1 if the option was one of the shared ones, 0 if not, -1 on a bad value. */
static inline int bench_common_opt(bench_opts *o, int opt, const char *arg)
{
    uint64_t u;
    char *end;
    switch (opt) {
    case BO_NAME: o->name = arg; return 1;
    case BO_DUMP: o->dump = arg; return 1;
    case BO_CPU: {
        o->cpu_list = arg;
        long a = strtol(arg, &end, 10);
        if (end == arg || a < 0)
            return -1;
        o->cpu[0] = (int)a;
        if (*end == ',') {
            const char *b = end + 1;
            long c = strtol(b, &end, 10);
            if (end == b || c < 0)
                return -1;
            o->cpu[1] = (int)c;
        }
        return *end ? -1 : 1;
    }
    case BO_PRIO:
        if (bench_parse_u64(arg, &u) || u > 99)
            return -1;
        o->prio = (int)u;
        return 1;
    case BO_PAYLOAD:
        if (bench_parse_u64(arg, &u) || u > 65000)
            return -1;
        o->payload = (long)u;
        return 1;
    case BO_RATE:
        o->rate_hz = strtod(arg, &end);
        return (*end || o->rate_hz < 0) ? -1 : 1;
    case BO_COUNT:
        if (bench_parse_u64(arg, &u) || u == 0 || u > 100000000ULL)
            return -1;
        o->count = u;
        return 1;
    case BO_WARMUP:
        if (bench_parse_u64(arg, &u) || u > 100000000ULL)
            return -1;
        o->warmup = u;
        return 1;
    case BO_TIMEOUT:
        if (bench_parse_u64(arg, &u) || u == 0)
            return -1;
        o->timeout_ns = (int64_t)u * 1000000LL;
        return 1;
    case BO_HALF: o->half = 1; return 1;
    case BO_NO_MLOCK: o->no_mlock = 1; return 1;
    default: return 0;
    }
}

/* A bad option value ends the program the same way in every program: the option as
 * written, the value, exit BENCH_EXIT_USAGE. Only right after getopt_long returned the
 * option: `--opt value` leaves the option at argv[optind - 2], `--opt=value` at optind - 1. */
__attribute__((noreturn)) static inline void bench_bad_value(char **argv, const char *arg)
{
    const char *written = arg && optind >= 2 && argv[optind - 1] == arg ? argv[optind - 2] : argv[optind - 1];
    fprintf(stderr, "bad value for option %s: %s\n", written, arg ? arg : "");
    exit(BENCH_EXIT_USAGE);
}

/*
 * The command-line protocol of every floor and peer program, getopt_long style: returns
 * the next option that is the program's own (-1 at the end). The shared options go into
 * *o; --help prints usage to stdout and exits 0; an unknown option or a positional
 * argument prints usage to stderr and a bad shared value says which, both exiting
 * BENCH_EXIT_USAGE. `longopts` starts with BENCH_COMMON_LONGOPTS.
 */
static inline int bench_next_opt(int argc, char **argv, const struct option *longopts, bench_opts *o,
                                 void (*usage)(FILE *))
{
    int opt;
    while ((opt = getopt_long(argc, argv, "", longopts, NULL)) != -1) {
        int r = bench_common_opt(o, opt, optarg);
        if (r < 0)
            bench_bad_value(argv, optarg);
        if (r == 1)
            continue;
        if (opt == BO_HELP) {
            usage(stdout);
            exit(BENCH_EXIT_OK);
        }
        if (opt < 0x200) { /* '?': unknown option or missing value */
            usage(stderr);
            exit(BENCH_EXIT_USAGE);
        }
        return opt;
    }
    if (optind != argc) {
        usage(stderr);
        exit(BENCH_EXIT_USAGE);
    }
    return -1;
}

/* The value of a mode option (e.g. --role echo|ping) as an index into the NULL-terminated
 * `words`, in the order of the program's enum; ends the program on another word. */
static inline int bench_choice_opt(char **argv, const char *arg, const char *const *words)
{
    int k = bench_choice(arg, words);
    if (k < 0)
        bench_bad_value(argv, arg);
    return k;
}

/* The value of a milliseconds option in nanoseconds; 0 only where `zero_ok`. */
static inline int64_t bench_ms_opt(char **argv, const char *arg, int zero_ok)
{
    uint64_t ms;
    if (bench_parse_u64(arg, &ms) || (ms == 0 && !zero_ok) || ms > (uint64_t)INT64_MAX / 1000000u)
        bench_bad_value(argv, arg);
    return (int64_t)ms * 1000000LL;
}

/* ---- real-time set-up ---- */

typedef struct {
    int cpu;      /* pinned CPU or -1 */
    int prio;     /* SCHED_FIFO priority obtained, 0 if none */
    int mlocked;  /* mlockall succeeded */
} bench_rt;

/* Pin, raise priority and lock memory where permitted; failures are reported in the
 * result (and on stderr), not fatal, so the same binary runs unprivileged. */
static inline bench_rt bench_rt_setup(int cpu, int prio, int want_mlock)
{
    bench_rt r = {-1, 0, 0};
    if (cpu >= 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(cpu, &set);
        if (sched_setaffinity(0, sizeof set, &set) == 0)
            r.cpu = cpu;
        else
            fprintf(stderr, "warning: cannot pin to CPU %d: %s\n", cpu, strerror(errno));
    }
    if (prio > 0) {
        struct sched_param sp;
        memset(&sp, 0, sizeof sp);
        sp.sched_priority = prio;
        if (sched_setscheduler(0, SCHED_FIFO, &sp) == 0)
            r.prio = prio;
        else
            fprintf(stderr, "warning: SCHED_FIFO %d refused: %s\n", prio, strerror(errno));
    }
    if (want_mlock) {
        if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0)
            r.mlocked = 1;
        else
            fprintf(stderr, "note: mlockall not permitted (%s); running unlocked\n", strerror(errno));
    }
    return r;
}

/* Maps the shared-memory object `name` (created zeroed if missing) of `size` bytes, read
 * and write; ends the program on failure. Both sides of an exchange may call it first. */
static inline void *bench_shm_map(const char *name, size_t size)
{
    int fd = shm_open(name, O_RDWR | O_CREAT, 0600);
    if (fd < 0)
        bench_die("shm_open %s: %s", name, strerror(errno));
    if (ftruncate(fd, (off_t)size) != 0)
        bench_die("ftruncate %s: %s", name, strerror(errno));
    void *p = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    close(fd);
    if (p == MAP_FAILED)
        bench_die("mmap %s: %s", name, strerror(errno));
    return p;
}

/* Removes the shared-memory object `name` (its mappings stay valid). */
static inline void bench_shm_remove(const char *name)
{
    shm_unlink(name);
}

/* Number of CPUs this process may run on (for the two-core sanity checks). */
static inline int bench_cpus_allowed(void)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) != 0)
        return 1;
    return CPU_COUNT(&set);
}

/* ---- result line ---- */

static inline void bench_json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/*
 * One JSON object per line on stdout, the schema the driver (scripts/bench-floors)
 * and later ccomm rows share: name, transport, payload_bytes, rate_hz, min/p50/p90/
 * p99/p999/max/mean in ns, count, lost; then metric ("rtt", "rtt_half", "one_way")
 * and whatever the program adds in `extra` (a JSON fragment starting with a comma).
 */
/* The end of every ping program: halve the round trips if --half, write the raw samples
 * if --dump, and summarize the measured ones (after the warm-up). */
static inline bench_stats bench_finish_samples(const bench_opts *o, bench_samples *s, uint64_t total)
{
    if (o->half)
        for (size_t i = 0; i < s->cap; i++)
            if (s->v[i] != BENCH_MISSING)
                s->v[i] /= 2;
    if (o->dump)
        bench_dump(o->dump, s, (size_t)o->warmup, (size_t)total);
    return bench_summarize(s, (size_t)o->warmup, (size_t)total);
}

static inline void bench_print_result(const char *name, const char *transport, const bench_opts *o,
                                      const char *metric, const bench_stats *st, const bench_rt *rt,
                                      const char *extra)
{
    FILE *f = stdout;
    fputs("{\"name\":", f);
    bench_json_str(f, name);
    fputs(",\"transport\":", f);
    bench_json_str(f, transport);
    fprintf(f, ",\"payload_bytes\":%ld,\"rate_hz\":%g", o->payload, o->rate_hz);
    fprintf(f,
            ",\"min_ns\":%" PRId64 ",\"p50_ns\":%" PRId64 ",\"p90_ns\":%" PRId64 ",\"p99_ns\":%" PRId64
            ",\"p999_ns\":%" PRId64 ",\"max_ns\":%" PRId64 ",\"mean_ns\":%.1f,\"count\":%" PRIu64
            ",\"lost\":%" PRIu64,
            st->min, st->p50, st->p90, st->p99, st->p999, st->max, st->mean, st->count, st->lost);
    fputs(",\"metric\":", f);
    bench_json_str(f, metric);
    fprintf(f, ",\"warmup\":%" PRIu64 ",\"cpu\":%d,\"prio\":%d,\"mlocked\":%s", o->warmup, rt ? rt->cpu : -1,
            rt ? rt->prio : 0, (rt && rt->mlocked) ? "true" : "false");
    if (extra && *extra)
        fputs(extra, f);
    fputs("}\n", f);
    fflush(f);
}

/* ---- signals: let blocking loops stop cleanly on SIGINT/SIGTERM ---- */

static volatile sig_atomic_t bench_stop_flag;

static inline void bench_on_signal(int sig)
{
    (void)sig;
    bench_stop_flag = 1;
}

/* No SA_RESTART, so blocking recv/poll return EINTR and the loop sees the flag. */
static inline void bench_install_stop_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = bench_on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

#endif /* CCOMM_BENCH_COMMON_H */
