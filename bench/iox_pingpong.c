/* SPDX-License-Identifier: Apache-2.0 */
/*
 * iox_pingpong: the iceoryx (classic, Debian 2.0.3) peer, shared-memory publish/
 * subscribe between two processes on this machine, same bench header and payloads
 * as the other programs. Needs a running iox-roudi (scripts/bench-floors starts one
 * with a private config and stops it again).
 *
 *   --role echo   take every chunk of CcbBench/Ping/Data, publish a copy on .../Pong
 *   --role ping   publish on .../Ping at --rate HZ (0 = back-to-back), record the
 *                 round trip of each answer on .../Pong
 *   --wait spin   poll iox_sub_take_chunk (like the shm_floor spin floor)
 *   --wait waitset  sleep in an iceoryx WaitSet (like the futex floor)
 * Chunks are loaned and published in place (zero copy); the echo copies the payload
 * into a fresh chunk because it answers on another service.
 */
#include "bench_common.h"

#include <iceoryx_binding_c/publisher.h>
#include <iceoryx_binding_c/runtime.h>
#include <iceoryx_binding_c/subscriber.h>
#include <iceoryx_binding_c/wait_set.h>

#define PROBE_SEQ UINT64_MAX
#define SERVICE "CcbBench"

enum role { R_ECHO, R_PING };
enum waitmode { W_SPIN, W_WAITSET };

struct node {
    iox_pub_storage_t pub_storage;
    iox_sub_storage_t sub_storage;
    iox_ws_storage_t ws_storage;
    iox_pub_t pub;
    iox_sub_t sub;
    iox_ws_t ws;
    enum waitmode wait;
};

/* Take the next chunk, waiting until `deadline` (0 = until a stop signal).
 * Returns NULL on timeout or stop. */
static const void *take(struct node *n, int64_t deadline)
{
    const void *chunk = NULL;
    unsigned spins = 0;
    for (;;) {
        if (iox_sub_take_chunk(n->sub, &chunk) == ChunkReceiveResult_SUCCESS)
            return chunk;
        if (bench_stop_flag)
            return NULL;
        if (n->wait == W_SPIN) {
            bench_cpu_relax();
            if ((++spins & 1023u) == 0 && deadline && bench_now_ns() > deadline)
                return NULL;
            continue;
        }
        int64_t left = deadline ? deadline - bench_now_ns() : 100000000; /* recheck stop flag */
        if (left <= 0)
            return NULL;
        iox_notification_info_t info[2];
        uint64_t missed = 0;
        iox_ws_timed_wait(n->ws, bench_ts_from_ns(left), info, 2, &missed);
    }
}

static int publish_copy(struct node *n, const void *src, uint32_t len, uint32_t type)
{
    void *chunk = NULL;
    if (iox_pub_loan_chunk(n->pub, &chunk, len) != AllocationResult_SUCCESS)
        return -1;
    memcpy(chunk, src, len);
    bench_put_u32((unsigned char *)chunk + 4, type);
    iox_pub_publish_chunk(n->pub, chunk);
    return 0;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: iox_pingpong --role echo|ping [--wait spin|waitset] [options]\n"
            "  --wait MODE        spin (default) or waitset\n"
            "  --persist          echo: keep serving after a FIN\n"
            "  --start-wait-ms MS ping: how long to wait for the echo (default 10000)\n" BENCH_COMMON_HELP
            "Needs a running iox-roudi.\n");
}

int main(int argc, char **argv)
{
    static struct node n;
    bench_opts o;
    bench_opts_defaults(&o, NULL, 8, 100000);
    o.rate_hz = 0;
    enum role role = R_PING;
    int have_role = 0, persist = 0;
    int64_t start_wait = 10000000000LL;
    n.wait = W_SPIN;
    enum { OPT_ROLE = 0x200, OPT_WAIT, OPT_PERSIST, OPT_START };
    static const struct option longopts[] = {BENCH_COMMON_LONGOPTS,
                                             {"role", required_argument, 0, OPT_ROLE},
                                             {"wait", required_argument, 0, OPT_WAIT},
                                             {"persist", no_argument, 0, OPT_PERSIST},
                                             {"start-wait-ms", required_argument, 0, OPT_START},
                                             {0, 0, 0, 0}};
    static const char *const roles[] = {"echo", "ping", NULL};    /* enum role */
    static const char *const waits[] = {"spin", "waitset", NULL}; /* enum waitmode */
    int opt;
    while ((opt = bench_next_opt(argc, argv, longopts, &o, usage)) != -1) {
        switch (opt) {
        case OPT_ROLE:
            role = (enum role)bench_choice_opt(argv, optarg, roles);
            have_role = 1;
            break;
        case OPT_WAIT: n.wait = (enum waitmode)bench_choice_opt(argv, optarg, waits); break;
        case OPT_PERSIST: persist = 1; break;
        case OPT_START: start_wait = bench_ms_opt(argv, optarg, 1); break;
        }
    }
    if (!have_role) {
        usage(stderr);
        return BENCH_EXIT_USAGE;
    }
    char defname[48];
    snprintf(defname, sizeof defname, "iox_%s", n.wait == W_SPIN ? "spin" : "waitset");
    if (!o.name)
        o.name = defname;
    uint32_t len = (uint32_t)(BENCH_HDR_SIZE + (size_t)o.payload);

    /* Runtime names must be unique per RouDi; the pid keeps parallel pairs apart. */
    char rtname[64];
    snprintf(rtname, sizeof rtname, "ccb_iox_%s_%d", role == R_ECHO ? "echo" : "ping", (int)getpid());
    iox_runtime_init(rtname);

    iox_pub_options_t po;
    iox_pub_options_init(&po);
    po.historyCapacity = 0;
    iox_sub_options_t so;
    iox_sub_options_init(&so);
    so.queueCapacity = 16;
    so.historyRequest = 0;
    n.pub = iox_pub_init(&n.pub_storage, SERVICE, role == R_ECHO ? "Pong" : "Ping", "Data", &po);
    n.sub = iox_sub_init(&n.sub_storage, SERVICE, role == R_ECHO ? "Ping" : "Pong", "Data", &so);
    if (n.wait == W_WAITSET) {
        n.ws = iox_ws_init(&n.ws_storage);
        if (iox_ws_attach_subscriber_state(n.ws, n.sub, SubscriberState_HAS_DATA, 0, NULL) != WaitSetResult_SUCCESS)
            bench_die("cannot attach the subscriber to the WaitSet");
    }
    bench_rt rt = bench_rt_setup(o.cpu[0], o.prio, !o.no_mlock);
    bench_install_stop_handlers();

    if (role == R_ECHO) {
        uint64_t echoed = 0;
        for (;;) {
            const void *c = take(&n, 0);
            if (!c)
                break;
            uint32_t type;
            uint64_t seq;
            int64_t t;
            int fin = 0;
            /* The chunk's payload size is what the publisher loaned; the header says the rest. */
            if (bench_hdr_read((const unsigned char *)c, BENCH_HDR_SIZE, &type, &seq, &t) == 0) {
                if (type == BENCH_MSG_PING) {
                    if (publish_copy(&n, c, len, BENCH_MSG_PONG) < 0)
                        fprintf(stderr, "echo: loan failed\n");
                    else if (seq != PROBE_SEQ)
                        echoed++;
                } else if (type == BENCH_MSG_FIN) {
                    fin = 1;
                }
            }
            iox_sub_release_chunk(n.sub, c);
            if (fin && !persist)
                break;
        }
        fprintf(stderr, "{\"role\":\"echo\",\"echoed\":%" PRIu64 "}\n", echoed);
    } else {
        uint64_t total = o.warmup + o.count;
        bench_samples s;
        bench_samples_init(&s, (size_t)total);
        unsigned char *m = (unsigned char *)calloc(1, len);
        if (!m)
            bench_die("out of memory");
        for (uint32_t i = BENCH_HDR_SIZE; i < len; i++)
            m[i] = (unsigned char)i;
        /* Wait for both connections, then one probe round trip, before measuring. */
        int64_t give_up = bench_now_ns() + start_wait;
        int ready = 0;
        while (!ready && bench_now_ns() < give_up && !bench_stop_flag) {
            if (iox_pub_has_subscribers(n.pub) &&
                iox_sub_get_subscription_state(n.sub) == SubscribeState_SUBSCRIBED) {
                bench_hdr_write(m, BENCH_MSG_PING, PROBE_SEQ, bench_now_ns());
                publish_copy(&n, m, len, BENCH_MSG_PING);
                const void *c = take(&n, bench_now_ns() + 20000000);
                if (c) {
                    iox_sub_release_chunk(n.sub, c);
                    ready = 1;
                }
            } else {
                bench_sleep_until(bench_now_ns() + 10000000);
            }
        }
        if (!ready) {
            fprintf(stderr, "iox ping: no echo within %" PRId64 " ms\n", start_wait / 1000000);
            iox_runtime_shutdown();
            return BENCH_EXIT_FAIL;
        }
        int64_t period = o.rate_hz > 0 ? (int64_t)(1e9 / o.rate_hz) : 0;
        int64_t t0 = bench_now_ns() + 1000000;
        uint64_t sent = 0, received = 0, foreign = 0, alloc_fail = 0;
        for (uint64_t i = 0; i < total && !bench_stop_flag; i++) {
            if (period)
                bench_sleep_until(t0 + (int64_t)i * period);
            int64_t ts = bench_now_ns();
            void *chunk = NULL;
            if (iox_pub_loan_chunk(n.pub, &chunk, len) != AllocationResult_SUCCESS) {
                alloc_fail++;
                continue;
            }
            memcpy((unsigned char *)chunk + BENCH_HDR_SIZE, m + BENCH_HDR_SIZE, len - BENCH_HDR_SIZE);
            bench_hdr_write((unsigned char *)chunk, BENCH_MSG_PING, i, ts);
            iox_pub_publish_chunk(n.pub, chunk);
            sent++;
            /* Shared memory delivers in order: wait for this answer, drop stale ones. */
            int64_t deadline = ts + o.timeout_ns;
            for (;;) {
                const void *c = take(&n, deadline);
                int64_t tr = bench_now_ns();
                if (!c)
                    break;
                uint32_t type;
                uint64_t seq;
                int64_t t;
                int mine = bench_hdr_read((const unsigned char *)c, BENCH_HDR_SIZE, &type, &seq, &t) == 0 &&
                           type == BENCH_MSG_PONG && seq == i;
                iox_sub_release_chunk(n.sub, c);
                if (mine) {
                    s.v[i] = tr - ts;
                    received++;
                    break;
                }
                foreign++;
            }
        }
        bench_hdr_write(m, BENCH_MSG_FIN, sent, bench_now_ns());
        publish_copy(&n, m, len, BENCH_MSG_FIN);
        bench_stats st = bench_finish_samples(&o, &s, total);
        char extra[256];
        snprintf(extra, sizeof extra,
                 ",\"program\":\"iox_pingpong\",\"wait\":\"%s\",\"sent\":%" PRIu64 ",\"foreign\":%" PRIu64
                 ",\"alloc_fail\":%" PRIu64,
                 n.wait == W_SPIN ? "spin" : "waitset", sent, foreign, alloc_fail);
        bench_print_result(o.name, "iceoryx", &o, o.half ? "rtt_half" : "rtt", &st, &rt, extra);
        /* Give the echo a moment to take the FIN before our ports go away. */
        bench_sleep_until(bench_now_ns() + 20000000);
        if (!received) {
            iox_runtime_shutdown();
            return BENCH_EXIT_FAIL;
        }
    }
    if (n.ws)
        iox_ws_deinit(n.ws);
    iox_sub_deinit(n.sub);
    iox_pub_deinit(n.pub);
    iox_runtime_shutdown();
    return BENCH_EXIT_OK;
}
