/* SPDX-License-Identifier: Apache-2.0 */
/*
 * net_floor: the plain-socket network floor, raw Ethernet (AF_PACKET) or UDP/IPv4,
 * blocking sockets, no daemon. ccomm's own forwarding is compared with this.
 *
 * Roles:
 *   echo    answer every PING with a PONG carrying the same bytes (exits on FIN
 *           unless --persist)
 *   ping    send PINGs periodically (--rate HZ, absolute sleeps like a control loop;
 *           --rate 0 = next one as soon as the reply is in) and record each round trip;
 *           a reply later than --timeout-ms counts as lost
 *   source  send DATA messages periodically carrying the send time
 *   sink    record now - send time per DATA message: one-way latency, valid only
 *           when both ends read the same CLOCK_MONOTONIC (one machine, two netns)
 * ping and source first probe until the other end answers, so start order does not
 * matter. Only libc: this file is also cross-compiled for 32-bit ARM
 * (`cc -O2 -o net_floor net_floor.c` with bench_common.h beside it), which is why all
 * four roles and both transports stay in this one file.
 */
#include "bench_common.h"

#include <arpa/inet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>

#include <linux/if_ether.h>
#include <linux/if_packet.h>

#define DEFAULT_ETHERTYPE 0x88B6 /* IEEE local experimental; ccomm itself uses 0x88B5 */
#define DEFAULT_UDP_PORT 47900   /* ccomm uses 47800 */
#define MAX_FRAME 2048
#define MIN_FRAME 60 /* Ethernet minimum without FCS: shorter frames are padded */
#define PROBE_SEQ UINT64_MAX

enum transport { T_RAW, T_UDP };
enum role { R_ECHO, R_PING, R_SOURCE, R_SINK };
static const char *const role_names[] = {"echo", "ping", "source", "sink"};

struct endpoint {
    enum transport t;
    int fd;
    /* raw */
    int ifindex;
    uint16_t ethertype;
    unsigned char own_mac[6];
    unsigned char dst_mac[6];
    int dst_given;
    const char *ifname;
    /* udp */
    struct sockaddr_in bind_addr;
    struct sockaddr_in peer;
    int peer_given;
    /* last sender, where echo/sink replies go */
    unsigned char from_mac[6];
    struct sockaddr_in from;
};

static void usage(FILE *f)
{
    fprintf(f,
            "usage: net_floor --transport raw|udp --role echo|ping|source|sink [options]\n"
            "  raw:  --if IFNAME [--ethertype 0x88B6] [--dst MAC|broadcast]\n"
            "  udp:  [--bind ADDR:PORT] (echo/sink default 0.0.0.0:%d) --peer ADDR:PORT (ping/source)\n"
            "  --persist          echo: keep serving after a FIN\n"
            "  --echo-limit N     echo: exit after answering N PINGs (tests of loss accounting)\n"
            "  --idle-ms MS       echo/sink: exit after MS without traffic once started (default 0 = never\n"
            "                     for echo, 2000 for sink)\n"
            "  --start-wait-ms MS ping/source: how long to probe for the peer (default 10000)\n" BENCH_COMMON_HELP
            "Defaults: --rate 1000 --count 10000 --warmup 100 --payload 8 --timeout-ms 1000.\n"
            "Every message carries a %u-byte bench header (magic, type, sequence, send time) before\n"
            "the payload; raw frames are padded to the 60-byte Ethernet minimum.\n"
            "Exit codes: 0 ok, 1 failure, 2 usage, 4 skipped (no permission for raw sockets).\n",
            DEFAULT_UDP_PORT, BENCH_HDR_SIZE);
}

static int parse_mac(const char *s, unsigned char mac[6])
{
    unsigned v[6];
    if (!strcmp(s, "broadcast")) {
        memset(mac, 0xff, 6);
        return 0;
    }
    if (sscanf(s, "%x:%x:%x:%x:%x:%x", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) != 6)
        return -1;
    for (int i = 0; i < 6; i++) {
        if (v[i] > 255)
            return -1;
        mac[i] = (unsigned char)v[i];
    }
    return 0;
}

static int parse_addr(const char *s, struct sockaddr_in *a)
{
    char host[64];
    const char *colon = strrchr(s, ':');
    if (!colon || (size_t)(colon - s) >= sizeof host)
        return -1;
    memcpy(host, s, (size_t)(colon - s));
    host[colon - s] = 0;
    uint64_t port;
    if (bench_parse_u64(colon + 1, &port) || port > 65535)
        return -1;
    memset(a, 0, sizeof *a);
    a->sin_family = AF_INET;
    a->sin_port = htons((uint16_t)port);
    if (host[0] == 0)
        a->sin_addr.s_addr = htonl(INADDR_ANY);
    else if (inet_pton(AF_INET, host, &a->sin_addr) != 1)
        return -1;
    return 0;
}

static int open_endpoint(struct endpoint *e, enum role r)
{
    if (e->t == T_RAW) {
        e->fd = socket(AF_PACKET, SOCK_RAW | SOCK_CLOEXEC, htons(e->ethertype));
        if (e->fd < 0) {
            fprintf(stderr, "AF_PACKET socket: %s%s\n", strerror(errno),
                    errno == EPERM ? " (needs root or CAP_NET_RAW)" : "");
            return errno == EPERM ? BENCH_EXIT_SKIP : BENCH_EXIT_FAIL;
        }
        struct ifreq ifr;
        memset(&ifr, 0, sizeof ifr);
        if (strlen(e->ifname) >= IFNAMSIZ) {
            fprintf(stderr, "interface name too long\n");
            return BENCH_EXIT_USAGE;
        }
        strcpy(ifr.ifr_name, e->ifname);
        if (ioctl(e->fd, SIOCGIFINDEX, &ifr) < 0) {
            fprintf(stderr, "interface %s: %s\n", e->ifname, strerror(errno));
            return BENCH_EXIT_FAIL;
        }
        e->ifindex = ifr.ifr_ifindex;
        if (ioctl(e->fd, SIOCGIFHWADDR, &ifr) < 0) {
            fprintf(stderr, "MAC of %s: %s\n", e->ifname, strerror(errno));
            return BENCH_EXIT_FAIL;
        }
        memcpy(e->own_mac, ifr.ifr_hwaddr.sa_data, 6);
        struct sockaddr_ll sll;
        memset(&sll, 0, sizeof sll);
        sll.sll_family = AF_PACKET;
        sll.sll_protocol = htons(e->ethertype);
        sll.sll_ifindex = e->ifindex;
        if (bind(e->fd, (struct sockaddr *)&sll, sizeof sll) < 0) {
            fprintf(stderr, "bind to %s: %s\n", e->ifname, strerror(errno));
            return BENCH_EXIT_FAIL;
        }
        if (!e->dst_given)
            memset(e->dst_mac, 0xff, 6);
        return 0;
    }
    e->fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (e->fd < 0) {
        fprintf(stderr, "UDP socket: %s\n", strerror(errno));
        return BENCH_EXIT_FAIL;
    }
    int one = 1;
    setsockopt(e->fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (bind(e->fd, (struct sockaddr *)&e->bind_addr, sizeof e->bind_addr) < 0) {
        fprintf(stderr, "bind UDP: %s\n", strerror(errno));
        return BENCH_EXIT_FAIL;
    }
    if (r == R_PING || r == R_SOURCE) {
        if (!e->peer_given) {
            fprintf(stderr, "--peer ADDR:PORT is required for %s over UDP\n", role_names[r]);
            return BENCH_EXIT_USAGE;
        }
        /* connect(): the kernel filters foreign senders and send() needs no address. */
        if (connect(e->fd, (struct sockaddr *)&e->peer, sizeof e->peer) < 0) {
            fprintf(stderr, "connect UDP: %s\n", strerror(errno));
            return BENCH_EXIT_FAIL;
        }
    }
    return 0;
}

/* Send a bench message (header + payload). For raw frames the Ethernet header is
 * written here; `to_mac` NULL means the configured destination. */
static int send_msg(struct endpoint *e, unsigned char *buf, size_t len, const unsigned char *to_mac,
                    const struct sockaddr_in *to)
{
    ssize_t n;
    if (e->t == T_RAW) {
        /* buf has ETH_HLEN bytes reserved in front of the message. */
        unsigned char *fr = buf - ETH_HLEN;
        memcpy(fr, to_mac ? to_mac : e->dst_mac, 6);
        memcpy(fr + 6, e->own_mac, 6);
        fr[12] = (unsigned char)(e->ethertype >> 8);
        fr[13] = (unsigned char)e->ethertype;
        size_t flen = len + ETH_HLEN;
        if (flen < MIN_FRAME) {
            memset(fr + flen, 0, MIN_FRAME - flen);
            flen = MIN_FRAME;
        }
        struct sockaddr_ll sll;
        memset(&sll, 0, sizeof sll);
        sll.sll_family = AF_PACKET;
        sll.sll_protocol = htons(e->ethertype);
        sll.sll_ifindex = e->ifindex;
        sll.sll_halen = 6;
        memcpy(sll.sll_addr, fr, 6);
        n = sendto(e->fd, fr, flen, 0, (struct sockaddr *)&sll, sizeof sll);
        return n == (ssize_t)flen ? 0 : -1;
    }
    if (to)
        n = sendto(e->fd, buf, len, 0, (const struct sockaddr *)to, sizeof *to);
    else
        n = send(e->fd, buf, len, 0);
    return n == (ssize_t)len ? 0 : -1;
}

/* Receive one bench message into buf (message starts at buf, raw frames are
 * stripped of their Ethernet header). Blocks until `deadline` (0 = forever).
 * Returns its length, 0 on timeout, -1 on interruption by a stop signal. */
static ssize_t recv_msg(struct endpoint *e, unsigned char *buf, size_t cap, int64_t deadline)
{
    unsigned char frame[MAX_FRAME];
    for (;;) {
        if (bench_stop_flag)
            return -1;
        ssize_t n;
        if (e->t == T_RAW) {
            struct sockaddr_ll from;
            socklen_t fl = sizeof from;
            n = recvfrom(e->fd, frame, sizeof frame, deadline ? MSG_DONTWAIT : 0, (struct sockaddr *)&from, &fl);
            if (n >= 0) {
                /* Our own transmissions are not for us (only seen by ETH_P_ALL taps, but be sure). */
                if (from.sll_pkttype == PACKET_OUTGOING || n < ETH_HLEN + (ssize_t)BENCH_HDR_SIZE)
                    continue;
                memcpy(e->from_mac, frame + 6, 6);
                n -= ETH_HLEN;
                if ((size_t)n > cap)
                    n = (ssize_t)cap;
                memcpy(buf, frame + ETH_HLEN, (size_t)n);
                return n;
            }
        } else {
            socklen_t fl = sizeof e->from;
            n = recvfrom(e->fd, buf, cap, deadline ? MSG_DONTWAIT : 0, (struct sockaddr *)&e->from, &fl);
            if (n >= (ssize_t)BENCH_HDR_SIZE)
                return n;
            if (n >= 0)
                continue;
        }
        if (errno == EINTR || errno == ECONNREFUSED) /* ICMP unreachable while the peer starts */
            continue;
        if (errno != EAGAIN && errno != EWOULDBLOCK) {
            fprintf(stderr, "recv: %s\n", strerror(errno));
            return -1;
        }
        int64_t left = deadline - bench_now_ns();
        if (left <= 0)
            return 0;
        struct pollfd p = {e->fd, POLLIN, 0};
        struct timespec ts = bench_ts_from_ns(left);
        if (ppoll(&p, 1, &ts, NULL) == 0)
            return 0;
    }
}

/* ---- roles ---- */

struct run {
    bench_opts o;
    enum role role;
    struct endpoint ep;
    int persist;
    uint64_t echo_limit; /* echo: exit after answering this many measured PINGs (0 = no limit) */
    int64_t idle_ns;
    int64_t start_wait_ns;
    size_t msg_len; /* header + payload */
    /* Message buffer with room for an Ethernet header in front. */
    unsigned char space[ETH_HLEN + MAX_FRAME];
};

static unsigned char *msgbuf(struct run *r) { return r->space + ETH_HLEN; }

static void reply(struct run *r, unsigned char *m, size_t len, uint32_t type)
{
    bench_put_u32(m + 4, type);
    if (send_msg(&r->ep, m, len, r->ep.t == T_RAW ? r->ep.from_mac : NULL, &r->ep.from) < 0)
        fprintf(stderr, "send reply: %s\n", strerror(errno));
}

static int run_echo(struct run *r)
{
    unsigned char *m = msgbuf(r);
    uint64_t echoed = 0;
    int64_t last = 0;
    for (;;) {
        int64_t deadline = (r->idle_ns && last) ? last + r->idle_ns : 0;
        ssize_t n = recv_msg(&r->ep, m, MAX_FRAME - ETH_HLEN, deadline);
        if (n < 0)
            break;
        if (n == 0) {
            fprintf(stderr, "echo: idle for %" PRId64 " ms, exiting\n", r->idle_ns / 1000000);
            break;
        }
        uint32_t type;
        uint64_t seq;
        int64_t t;
        if (bench_hdr_read(m, (size_t)n, &type, &seq, &t) < 0)
            continue;
        last = bench_now_ns();
        if (type == BENCH_MSG_PING) {
            reply(r, m, (size_t)n, BENCH_MSG_PONG);
            if (seq != PROBE_SEQ && ++echoed == r->echo_limit)
                break;
        } else if (type == BENCH_MSG_FIN && !r->persist) {
            break;
        }
    }
    fprintf(stderr, "{\"role\":\"echo\",\"echoed\":%" PRIu64 "}\n", echoed);
    return 0;
}

/* Probe until the other end answers, so the measured run starts with both sides up. */
static int wait_for_peer(struct run *r)
{
    unsigned char *m = msgbuf(r);
    int64_t give_up = bench_now_ns() + r->start_wait_ns;
    while (bench_now_ns() < give_up && !bench_stop_flag) {
        bench_hdr_write(m, BENCH_MSG_PING, PROBE_SEQ, bench_now_ns());
        if (send_msg(&r->ep, m, r->msg_len, NULL, NULL) < 0 && errno != ECONNREFUSED)
            fprintf(stderr, "send probe: %s\n", strerror(errno));
        int64_t until = bench_now_ns() + 20000000; /* 20 ms between probes */
        for (;;) {
            ssize_t n = recv_msg(&r->ep, m, MAX_FRAME - ETH_HLEN, until);
            if (n <= 0)
                break;
            uint32_t type;
            uint64_t seq;
            int64_t t;
            if (bench_hdr_read(m, (size_t)n, &type, &seq, &t) == 0 && type == BENCH_MSG_PONG && seq == PROBE_SEQ) {
                /* Let late probe answers drain so they do not meet the run. */
                while (recv_msg(&r->ep, m, MAX_FRAME - ETH_HLEN, bench_now_ns() + 30000000) > 0) {
                }
                return 0;
            }
        }
    }
    fprintf(stderr, "%s: no answer from the peer within %" PRId64 " ms\n", role_names[r->role],
            r->start_wait_ns / 1000000);
    return -1;
}

static void send_fin(struct run *r, uint64_t sent)
{
    unsigned char *m = msgbuf(r);
    /* Three times: a lost FIN only costs the receiver its idle timeout. */
    for (int i = 0; i < 3; i++) {
        bench_hdr_write(m, BENCH_MSG_FIN, sent, bench_now_ns());
        send_msg(&r->ep, m, r->msg_len, NULL, NULL);
    }
}

static const char *transport_name(const struct run *r) { return r->ep.t == T_RAW ? "raw" : "udp"; }

static size_t wire_bytes(const struct run *r)
{
    if (r->ep.t == T_RAW)
        return r->msg_len + ETH_HLEN < MIN_FRAME ? MIN_FRAME : r->msg_len + ETH_HLEN;
    size_t n = r->msg_len + ETH_HLEN + 20 + 8; /* + IPv4 + UDP headers */
    return n < MIN_FRAME ? MIN_FRAME : n;
}

static void print_run(struct run *r, bench_samples *s, bench_rt *rt, const char *metric, uint64_t sent,
                      uint64_t late, uint64_t foreign)
{
    bench_opts o = r->o;
    o.half = o.half && strcmp(metric, "one_way") != 0;  /* --half halves round trips only */
    bench_stats st = bench_finish_samples(&o, s, o.warmup + o.count);
    char extra[512];
    int k = snprintf(extra, sizeof extra,
                     ",\"program\":\"net_floor\",\"role\":\"%s\",\"wire_bytes\":%zu,\"sent\":%" PRIu64
                     ",\"late\":%" PRIu64 ",\"foreign\":%" PRIu64,
                     role_names[r->role], wire_bytes(r), sent, late, foreign);
    if (r->ep.t == T_RAW)
        snprintf(extra + k, sizeof extra - (size_t)k, ",\"iface\":\"%s\",\"ethertype\":\"0x%04X\"", r->ep.ifname,
                 r->ep.ethertype);
    bench_print_result(r->o.name, transport_name(r), &r->o, metric, &st, rt, extra);
}

static int run_ping(struct run *r, bench_rt *rt)
{
    uint64_t total = r->o.warmup + r->o.count;
    bench_samples s, tsend;
    bench_samples_init(&s, (size_t)total);
    bench_samples_init(&tsend, (size_t)total);
    unsigned char *m = msgbuf(r);
    unsigned char rx[MAX_FRAME];
    for (size_t i = BENCH_HDR_SIZE; i < r->msg_len; i++)
        m[i] = (unsigned char)i;
    if (wait_for_peer(r) < 0)
        return BENCH_EXIT_FAIL;

    int64_t period = r->o.rate_hz > 0 ? (int64_t)(1e9 / r->o.rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    uint64_t sent = 0, late = 0, foreign = 0, received = 0;
    for (uint64_t i = 0; i <= total && !bench_stop_flag; i++) {
        int64_t until; /* receive replies until then */
        if (i < total) {
            if (period)
                bench_sleep_until(t0 + (int64_t)i * period);
            int64_t ts = bench_now_ns();
            bench_hdr_write(m, BENCH_MSG_PING, i, ts);
            tsend.v[i] = ts;
            if (send_msg(&r->ep, m, r->msg_len, NULL, NULL) < 0)
                fprintf(stderr, "send: %s\n", strerror(errno));
            else
                sent++;
            until = period ? t0 + (int64_t)(i + 1) * period : ts + r->o.timeout_ns;
        } else {
            /* After the last send: wait for whatever can still arrive in time. */
            if (received == sent)
                break;
            until = tsend.v[total - 1] + r->o.timeout_ns;
        }
        for (;;) {
            if (!period && i < total && s.v[i] != BENCH_MISSING)
                break;
            if (i == total && received == sent)
                break;
            ssize_t n = recv_msg(&r->ep, rx, sizeof rx, until);
            int64_t tr = bench_now_ns();
            if (n <= 0)
                break;
            uint32_t type;
            uint64_t seq;
            int64_t t;
            if (bench_hdr_read(rx, (size_t)n, &type, &seq, &t) < 0 || type != BENCH_MSG_PONG || seq >= total ||
                tsend.v[seq] == BENCH_MISSING || s.v[seq] != BENCH_MISSING) {
                foreign++;
                continue;
            }
            if (tr - tsend.v[seq] > r->o.timeout_ns) {
                late++;
                continue;
            }
            s.v[seq] = tr - tsend.v[seq];
            received++;
        }
    }
    send_fin(r, sent);
    print_run(r, &s, rt, r->o.half ? "rtt_half" : "rtt", sent, late, foreign);
    return received ? BENCH_EXIT_OK : BENCH_EXIT_FAIL;
}

static int run_source(struct run *r)
{
    uint64_t total = r->o.warmup + r->o.count;
    unsigned char *m = msgbuf(r);
    for (size_t i = BENCH_HDR_SIZE; i < r->msg_len; i++)
        m[i] = (unsigned char)i;
    if (wait_for_peer(r) < 0)
        return BENCH_EXIT_FAIL;
    int64_t period = r->o.rate_hz > 0 ? (int64_t)(1e9 / r->o.rate_hz) : 0;
    int64_t t0 = bench_now_ns() + 1000000;
    uint64_t sent = 0;
    for (uint64_t i = 0; i < total && !bench_stop_flag; i++) {
        if (period)
            bench_sleep_until(t0 + (int64_t)i * period);
        bench_hdr_write(m, BENCH_MSG_DATA, i, bench_now_ns());
        if (send_msg(&r->ep, m, r->msg_len, NULL, NULL) == 0)
            sent++;
        else if (errno != ENOBUFS && errno != EAGAIN)
            fprintf(stderr, "send: %s\n", strerror(errno));
    }
    send_fin(r, sent);
    fprintf(stderr, "{\"role\":\"source\",\"sent\":%" PRIu64 "}\n", sent);
    return BENCH_EXIT_OK;
}

static int run_sink(struct run *r, bench_rt *rt)
{
    uint64_t total = r->o.warmup + r->o.count;
    bench_samples s;
    bench_samples_init(&s, (size_t)total);
    unsigned char *m = msgbuf(r);
    uint64_t received = 0, foreign = 0, fin_sent = 0;
    int64_t last = 0;
    int fin = 0;
    int64_t idle = r->idle_ns ? r->idle_ns : 2000000000LL;
    if (r->o.rate_hz > 0 && idle < (int64_t)(5e9 / r->o.rate_hz))
        idle = (int64_t)(5e9 / r->o.rate_hz);
    while (!bench_stop_flag) {
        ssize_t n = recv_msg(&r->ep, m, MAX_FRAME - ETH_HLEN, last ? last + idle : 0);
        int64_t tr = bench_now_ns();
        if (n < 0)
            break;
        if (n == 0) {
            fprintf(stderr, "sink: idle for %" PRId64 " ms, no FIN; stopping\n", idle / 1000000);
            break;
        }
        uint32_t type;
        uint64_t seq;
        int64_t t;
        if (bench_hdr_read(m, (size_t)n, &type, &seq, &t) < 0) {
            foreign++;
            continue;
        }
        if (type == BENCH_MSG_PING) { /* the source's start-up probe */
            reply(r, m, (size_t)n, BENCH_MSG_PONG);
            continue;
        }
        if (type == BENCH_MSG_FIN) {
            fin = 1;
            fin_sent = seq;
            break;
        }
        if (type != BENCH_MSG_DATA || seq >= total || s.v[seq] != BENCH_MISSING) {
            foreign++;
            continue;
        }
        last = tr;
        s.v[seq] = tr - t;
        received++;
    }
    /* Lost = what the source says it sent minus what arrived; without a FIN the
     * configured count is the best guess (BENCH_MISSING slots in the summary). */
    uint64_t sent = fin ? fin_sent : total;
    if (fin && fin_sent < total)
        fprintf(stderr, "sink: source sent only %" PRIu64 " of %" PRIu64 "\n", fin_sent, total);
    print_run(r, &s, rt, "one_way", sent, 0, foreign);
    return received ? BENCH_EXIT_OK : BENCH_EXIT_FAIL;
}

int main(int argc, char **argv)
{
    static struct run r; /* large buffer: static, not on the stack */
    bench_opts_defaults(&r.o, NULL, 8, 10000);
    r.o.rate_hz = 1000;
    r.start_wait_ns = 10000000000LL;
    r.ep.ethertype = DEFAULT_ETHERTYPE;
    r.ep.bind_addr.sin_family = AF_INET;
    int have_t = 0, have_r = 0, have_bind = 0;
    enum {
        OPT_T = 0x200, OPT_ROLE, OPT_IF, OPT_ET, OPT_DST, OPT_BIND, OPT_PEER, OPT_PERSIST, OPT_IDLE, OPT_START,
        OPT_LIMIT
    };
    static const struct option longopts[] = {BENCH_COMMON_LONGOPTS,
                                             {"transport", required_argument, 0, OPT_T},
                                             {"role", required_argument, 0, OPT_ROLE},
                                             {"if", required_argument, 0, OPT_IF},
                                             {"ethertype", required_argument, 0, OPT_ET},
                                             {"dst", required_argument, 0, OPT_DST},
                                             {"bind", required_argument, 0, OPT_BIND},
                                             {"peer", required_argument, 0, OPT_PEER},
                                             {"persist", no_argument, 0, OPT_PERSIST},
                                             {"echo-limit", required_argument, 0, OPT_LIMIT},
                                             {"idle-ms", required_argument, 0, OPT_IDLE},
                                             {"start-wait-ms", required_argument, 0, OPT_START},
                                             {0, 0, 0, 0}};
    static const char *const transports[] = {"raw", "udp", NULL};           /* enum transport */
    static const char *const roles[] = {"echo", "ping", "source", "sink", NULL}; /* enum role */
    int opt;
    uint64_t u;
    while ((opt = bench_next_opt(argc, argv, longopts, &r.o, usage)) != -1) {
        int bad = 0;
        switch (opt) {
        case OPT_T:
            r.ep.t = (enum transport)bench_choice_opt(argv, optarg, transports);
            have_t = 1;
            break;
        case OPT_ROLE:
            r.role = (enum role)bench_choice_opt(argv, optarg, roles);
            have_r = 1;
            break;
        case OPT_IF: r.ep.ifname = optarg; break;
        case OPT_ET:
            if (bench_parse_u64(optarg, &u) || u < 0x0600 || u > 0xFFFF)
                bench_bad_value(argv, optarg);
            r.ep.ethertype = (uint16_t)u;
            break;
        case OPT_DST:
            bad = parse_mac(optarg, r.ep.dst_mac) < 0;
            r.ep.dst_given = 1;
            break;
        case OPT_BIND:
            bad = parse_addr(optarg, &r.ep.bind_addr) < 0;
            have_bind = 1;
            break;
        case OPT_PEER:
            bad = parse_addr(optarg, &r.ep.peer) < 0;
            r.ep.peer_given = 1;
            break;
        case OPT_PERSIST: r.persist = 1; break;
        case OPT_LIMIT: bad = bench_parse_u64(optarg, &r.echo_limit) != 0; break;
        case OPT_IDLE: r.idle_ns = bench_ms_opt(argv, optarg, 1); break;
        case OPT_START: r.start_wait_ns = bench_ms_opt(argv, optarg, 1); break;
        }
        if (bad)
            bench_bad_value(argv, optarg);
    }
    if (!have_t || !have_r) {
        usage(stderr);
        return BENCH_EXIT_USAGE;
    }
    if (r.ep.t == T_RAW && !r.ep.ifname) {
        fprintf(stderr, "--if IFNAME is required for raw\n");
        return BENCH_EXIT_USAGE;
    }
    if (r.ep.t == T_UDP && !have_bind && (r.role == R_ECHO || r.role == R_SINK))
        r.ep.bind_addr.sin_port = htons(DEFAULT_UDP_PORT);
    r.msg_len = BENCH_HDR_SIZE + (size_t)r.o.payload;
    if (r.msg_len + ETH_HLEN > 1514) {
        fprintf(stderr, "payload too large for one Ethernet frame (max %u bytes)\n",
                1514u - ETH_HLEN - BENCH_HDR_SIZE - (r.ep.t == T_UDP ? 28u : 0u));
        return BENCH_EXIT_USAGE;
    }
    char defname[48];
    snprintf(defname, sizeof defname, "net_%s_%s", r.ep.t == T_RAW ? "raw" : "udp",
             r.role == R_SINK ? "oneway" : "rtt");
    if (!r.o.name)
        r.o.name = defname;

    int rc = open_endpoint(&r.ep, r.role);
    if (rc)
        return rc;
    bench_rt rt = bench_rt_setup(r.o.cpu[0], r.o.prio, !r.o.no_mlock);
    bench_install_stop_handlers();
    switch (r.role) {
    case R_ECHO: return run_echo(&r);
    case R_PING: return run_ping(&r, &rt);
    case R_SOURCE: return run_source(&r);
    case R_SINK: return run_sink(&r, &rt);
    }
    return BENCH_EXIT_FAIL;
}
