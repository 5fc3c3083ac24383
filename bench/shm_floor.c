/* SPDX-License-Identifier: Apache-2.0 */
/*
 * shm_floor: the shared-memory latency floor on this machine.
 *
 * Two processes (fork, MAP_SHARED memory, each pinned to its own CPU) hand a
 * cache line back and forth. The parent stamps, publishes a sequence number (and
 * the payload), the child notices, copies the payload and answers; the parent
 * records the round trip. Modes:
 *   spin     both sides busy-read the line: the cache-coherence floor
 *   futex    both sides sleep in FUTEX_WAIT and are woken by FUTEX_WAKE:
 *            the blocking wake-up floor
 *   eventfd  both sides sleep in read()/poll() on an eventfd: the wake-up floor of
 *            a file-descriptor based notification (what an epoll loop would pay)
 * With --half the reported value is RTT/2, the usual one-way estimate.
 */
#include "bench_common.h"

#include <linux/futex.h>
#include <poll.h>
#include <stdatomic.h>
#include <sys/eventfd.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>

enum mode { MODE_SPIN, MODE_FUTEX, MODE_EVENTFD };
static const char *const mode_names[] = {"spin", "futex", "eventfd"};

#define CACHE_LINE 64
#define STOP_SEQ 0xFFFFFFFFu /* odd, never a real request */
#define MAX_SHM_PAYLOAD 4096

/* The turn word and the payload share the first cache line when the payload fits
 * in the 56 bytes after the word; larger payloads spill into following lines. */
struct shm_area {
    _Alignas(CACHE_LINE) _Atomic uint32_t turn; /* odd = request seq*2+1, even = reply */
    uint32_t reply_seq;                          /* eventfd mode: which request was answered */
    unsigned char data[MAX_SHM_PAYLOAD];
};

static long futex_wait(_Atomic uint32_t *addr, uint32_t val, const struct timespec *rel)
{
    /* Not FUTEX_PRIVATE_FLAG: the word is shared between two processes. */
    return syscall(SYS_futex, (uint32_t *)addr, FUTEX_WAIT, val, rel, NULL, 0);
}

static long futex_wake(_Atomic uint32_t *addr)
{
    return syscall(SYS_futex, (uint32_t *)addr, FUTEX_WAKE, 1, NULL, NULL, 0);
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: shm_floor [--mode spin|futex|eventfd] [options]\n"
            "Round trip of one cache line between two processes on two CPUs.\n"
            "  --mode M           spin (default), futex or eventfd\n" BENCH_COMMON_HELP
            "Prints one JSON line (see bench_common.h).\n");
}

/* ---- the answering side (child) ---- */

static void pong_loop(struct shm_area *a, enum mode m, size_t payload, int efd_req, int efd_rep, int same_cpu)
{
    unsigned char local[MAX_SHM_PAYLOAD];
    uint32_t last = 0;
    for (;;) {
        uint32_t v;
        if (m == MODE_EVENTFD) {
            uint64_t cnt;
            if (read(efd_req, &cnt, sizeof cnt) != (ssize_t)sizeof cnt) {
                if (errno == EINTR)
                    continue;
                _exit(BENCH_EXIT_FAIL);
            }
            v = atomic_load_explicit(&a->turn, memory_order_acquire);
        } else {
            for (;;) {
                v = atomic_load_explicit(&a->turn, memory_order_acquire);
                if ((v & 1u) && v != last)
                    break;
                if (m == MODE_FUTEX)
                    futex_wait(&a->turn, v, NULL);
                else if (same_cpu)
                    sched_yield(); /* one CPU only: let the other side run */
                else
                    bench_cpu_relax();
            }
        }
        if (v == STOP_SEQ)
            _exit(0);
        if (!(v & 1u) || v == last)
            continue; /* eventfd counter coalesced two wakes; nothing new */
        last = v;
        /* Read the request payload and write the answer back, as a real consumer
         * and producer would; the copies keep the compiler honest. */
        memcpy(local, a->data, payload);
        memcpy(a->data, local, payload);
        a->reply_seq = v;
        atomic_store_explicit(&a->turn, v + 1, memory_order_release);
        if (m == MODE_FUTEX) {
            futex_wake(&a->turn);
        } else if (m == MODE_EVENTFD) {
            uint64_t one = 1;
            if (write(efd_rep, &one, sizeof one) != (ssize_t)sizeof one)
                _exit(BENCH_EXIT_FAIL);
        }
    }
}

/* ---- the measuring side (parent): returns 1 if the reply came in time ---- */

static int wait_reply(struct shm_area *a, enum mode m, uint32_t want, int64_t deadline, int efd_rep,
                      int same_cpu)
{
    if (m == MODE_EVENTFD) {
        for (;;) {
            int64_t left = deadline - bench_now_ns();
            if (left <= 0)
                return 0;
            struct pollfd p = {efd_rep, POLLIN, 0};
            struct timespec ts = bench_ts_from_ns(left);
            int r = ppoll(&p, 1, &ts, NULL);
            if (r < 0 && errno != EINTR)
                bench_die("ppoll: %s", strerror(errno));
            if (r <= 0)
                continue;
            uint64_t cnt;
            if (read(efd_rep, &cnt, sizeof cnt) != (ssize_t)sizeof cnt)
                continue;
            if (atomic_load_explicit(&a->turn, memory_order_acquire) == want && a->reply_seq + 1 == want)
                return 1;
        }
    }
    unsigned spins = 0;
    for (;;) {
        uint32_t v = atomic_load_explicit(&a->turn, memory_order_acquire);
        if (v == want)
            return 1;
        if (m == MODE_FUTEX) {
            int64_t left = deadline - bench_now_ns();
            if (left <= 0)
                return 0;
            struct timespec ts = bench_ts_from_ns(left);
            futex_wait(&a->turn, v, &ts);
        } else {
            if (same_cpu)
                sched_yield();
            else
                bench_cpu_relax();
            /* Reading the clock costs more than the line transfer: only now and then. */
            if ((++spins & 1023u) == 0 && bench_now_ns() > deadline)
                return 0;
        }
    }
}

int main(int argc, char **argv)
{
    bench_opts o;
    bench_opts_defaults(&o, NULL, 8, 100000);
    o.warmup = 1000;
    enum mode m = MODE_SPIN;
    enum { OPT_MODE = 0x200 };
    static const struct option longopts[] = {BENCH_COMMON_LONGOPTS,
                                             {"mode", required_argument, 0, OPT_MODE},
                                             {0, 0, 0, 0}};
    static const char *const modes[] = {"spin", "futex", "eventfd", NULL}; /* enum mode */
    int opt;
    while ((opt = bench_next_opt(argc, argv, longopts, &o, usage)) != -1)
        if (opt == OPT_MODE)
            m = (enum mode)bench_choice_opt(argv, optarg, modes);
    if (o.payload > MAX_SHM_PAYLOAD) {
        fprintf(stderr, "payload at most %d bytes\n", MAX_SHM_PAYLOAD);
        return BENCH_EXIT_USAGE;
    }
    char defname[32];
    snprintf(defname, sizeof defname, "shm_%s", mode_names[m]);
    if (!o.name)
        o.name = defname;

    /* Default placement: the first two CPUs we may use, one per side. */
    int allowed = bench_cpus_allowed();
    if (o.cpu[0] < 0 || o.cpu[1] < 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        sched_getaffinity(0, sizeof set, &set);
        int found = 0;
        for (int c = 0; c < CPU_SETSIZE && found < 2; c++) {
            if (!CPU_ISSET(c, &set))
                continue;
            if (found == 0 && o.cpu[0] < 0)
                o.cpu[0] = c;
            else if (o.cpu[1] < 0 && c != o.cpu[0])
                o.cpu[1] = c;
            found++;
        }
        if (o.cpu[1] < 0)
            o.cpu[1] = o.cpu[0];
    }
    int same_cpu = (o.cpu[0] == o.cpu[1]) || allowed < 2;
    if (same_cpu)
        fprintf(stderr, "warning: both sides on one CPU; spin mode yields and measures the scheduler\n");

    struct shm_area *a = mmap(NULL, sizeof *a, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (a == MAP_FAILED)
        bench_die("mmap: %s", strerror(errno));
    memset(a, 0, sizeof *a);
    int efd_req = -1, efd_rep = -1;
    if (m == MODE_EVENTFD) {
        efd_req = eventfd(0, EFD_CLOEXEC);
        efd_rep = eventfd(0, EFD_CLOEXEC);
        if (efd_req < 0 || efd_rep < 0)
            bench_die("eventfd: %s", strerror(errno));
    }

    uint64_t total = o.warmup + o.count;
    if (total * 2 + 1 >= STOP_SEQ)
        bench_die("too many messages for the 32-bit turn word");
    bench_samples s;
    bench_samples_init(&s, (size_t)total);

    pid_t parent = getpid();
    pid_t child = fork();
    if (child < 0)
        bench_die("fork: %s", strerror(errno));
    if (child == 0) {
        /* Die with the parent: a blocked futex/eventfd waiter would otherwise stay forever. */
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent)
            _exit(BENCH_EXIT_FAIL);
        bench_rt_setup(o.cpu[1], o.prio, !o.no_mlock);
        pong_loop(a, m, (size_t)o.payload, efd_req, efd_rep, same_cpu);
        _exit(0);
    }
    bench_rt rt = bench_rt_setup(o.cpu[0], o.prio, !o.no_mlock);
    bench_install_stop_handlers();

    unsigned char out[MAX_SHM_PAYLOAD], in[MAX_SHM_PAYLOAD];
    memset(in, 0, sizeof in);
    for (long i = 0; i < o.payload; i++)
        out[i] = (unsigned char)i;
    int64_t period = o.rate_hz > 0 ? (int64_t)(1e9 / o.rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    uint64_t consecutive_lost = 0;
    for (uint64_t i = 0; i < total && !bench_stop_flag; i++) {
        if (period)
            bench_sleep_until(t0 + (int64_t)i * period);
        uint32_t req = (uint32_t)(2 * i + 1);
        int64_t t1 = bench_now_ns();
        memcpy(a->data, out, (size_t)o.payload);
        atomic_store_explicit(&a->turn, req, memory_order_release);
        if (m == MODE_FUTEX) {
            futex_wake(&a->turn);
        } else if (m == MODE_EVENTFD) {
            uint64_t one = 1;
            if (write(efd_req, &one, sizeof one) != (ssize_t)sizeof one)
                bench_die("eventfd write: %s", strerror(errno));
        }
        if (wait_reply(a, m, req + 1, t1 + o.timeout_ns, efd_rep, same_cpu)) {
            int64_t t2 = bench_now_ns();
            memcpy(in, a->data, (size_t)o.payload);
            s.v[i] = t2 - t1;
            consecutive_lost = 0;
        } else if (++consecutive_lost >= 3) {
            fprintf(stderr, "no answer for 3 requests in a row; giving up\n");
            break;
        }
    }
    atomic_store_explicit(&a->turn, STOP_SEQ, memory_order_release);
    if (m == MODE_FUTEX)
        futex_wake(&a->turn);
    if (m == MODE_EVENTFD) {
        uint64_t one = 1;
        if (write(efd_req, &one, sizeof one) < 0)
            fprintf(stderr, "eventfd write: %s\n", strerror(errno));
    }
    int status = 0;
    waitpid(child, &status, 0);

    bench_stats st = bench_finish_samples(&o, &s, total);
    char extra[160];
    snprintf(extra, sizeof extra, ",\"program\":\"shm_floor\",\"mode\":\"%s\",\"peer_cpu\":%d,\"same_cpu\":%s",
             mode_names[m], o.cpu[1], same_cpu ? "true" : "false");
    bench_print_result(o.name, "shm", &o, o.half ? "rtt_half" : "rtt", &st, &rt, extra);
    if (in[0] != out[0] && o.payload > 0 && st.count)
        fprintf(stderr, "warning: payload came back changed\n");
    return (st.count == 0 || bench_stop_flag) ? BENCH_EXIT_FAIL : BENCH_EXIT_OK;
}
