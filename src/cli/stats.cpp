// SPDX-License-Identifier: Apache-2.0
// `ccomm stats`: the counters ccommd and the clients keep in shared memory.
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "ccomm/ccomm.h"
#include "common/platform.h"
#include "store/segment.h"

namespace st = ccomm::store;

namespace {

const char* const kCounterNames[] = {"frames_rx",      "frames_tx",       "frames_bad",      "frames_wrong_hash",
                                     "frames_unknown_sender", "frames_auth_failed", "frames_replayed",
                                     "frames_not_for_us", "entries_unknown_signal", "entries_wrong_type",
                                     "send_errors",    "tx_wakeups",      "recv_errors",     "slots_reclaimed",
                                     "socket_drops"};
static_assert(sizeof(kCounterNames) / sizeof(kCounterNames[0]) == st::kDaemonCounterCount, "names");

struct Snapshot {
  uint64_t t = 0;
  std::vector<uint64_t> sig_tx, sig_rx, sig_writes;
  std::vector<uint64_t> peer_rx, peer_tx;
};

Snapshot Take(const st::Segment& s) {
  Snapshot n;
  n.t = ccomm::platform::MonotonicNs();
  for (uint32_t i = 0; i < s.signal_count(); ++i) {
    n.sig_tx.push_back(s.stats(i).tx.load());
    n.sig_rx.push_back(s.stats(i).rx.load());
    n.sig_writes.push_back(s.stats(i).writes.load());
  }
  for (uint32_t p = 0; p < s.node_count(); ++p) {
    n.peer_rx.push_back(s.peer(p).frames_rx.load());
    n.peer_tx.push_back(s.peer(p).frames_tx.load());
  }
  return n;
}

// Age of a timestamp taken by ccommd after our snapshot time: 0, not 2^64 ns.
uint64_t Age(uint64_t now, uint64_t t) { return t >= now ? 0 : now - t; }

double Rate(uint64_t a, uint64_t b, double secs) { return secs > 0 ? static_cast<double>(b - a) / secs : 0; }

void Print(const st::Segment& s, const Snapshot* before, const Snapshot& now, bool json) {
  const st::SegmentHeader* h = s.header();
  double secs = before ? static_cast<double>(now.t - before->t) / 1e9 : 0;
  uint64_t mono = now.t;
  // The heartbeat may be newer than `mono` (taken before): that is alive, not 2^64 ns old.
  const uint64_t hb = h->daemon_heartbeat_ns.load();
  bool daemon = h->daemon_pid.load() != 0 && (hb >= mono || mono - hb < 1000000000ull);
  if (json) {
    printf("{\"node\":\"%s\",\"daemon_alive\":%s,\"generation\":%u,\"counters\":{", h->node_name,
           daemon ? "true" : "false", h->generation.load());
    for (uint32_t i = 0; i < st::kDaemonCounterCount; ++i)
      printf("%s\"%s\":%" PRIu64, i ? "," : "", kCounterNames[i], h->daemon_counters[i].load());
    printf("},\"peers\":[");
    bool first = true;
    for (uint32_t p = 0; p < s.node_count(); ++p) {
      if (p == h->node_id) continue;
      const st::PeerStats& ps = s.peer(p);
      uint64_t last = ps.last_rx_ns.load();
      printf("%s{\"name\":\"%s\",\"alive\":%s,\"frames_rx\":%" PRIu64 ",\"frames_tx\":%" PRIu64
             ",\"frames_lost\":%" PRIu64 ",\"frames_reordered\":%" PRIu64 ",\"heartbeats_rx\":%" PRIu64
             ",\"down_transitions\":%" PRIu64 ",\"last_rx_age_ms\":%.1f}",
             first ? "" : ",", s.node_name(p), ps.alive.load() ? "true" : "false", ps.frames_rx.load(),
             ps.frames_tx.load(), ps.frames_lost.load(), ps.frames_reordered.load(), ps.heartbeats_rx.load(),
             ps.down_transitions.load(), last ? static_cast<double>(Age(mono, last)) / 1e6 : -1.0);
      first = false;
    }
    printf("],\"signals\":[");
    for (uint32_t i = 0; i < s.signal_count(); ++i) {
      const st::SignalStats& ss = s.stats(i);
      const st::SignalDirectoryEntry& d = s.dir(i);
      uint64_t last = ss.last_rx_ns.load();
      bool stale = (d.flags & st::kSigConsumedHere) && d.stale_after_ms &&
                   (!last || Age(mono, last) > uint64_t{d.stale_after_ms} * 1000000);
      printf("%s{\"name\":\"%s\",\"writes\":%" PRIu64 ",\"write_errors\":%" PRIu64 ",\"tx\":%" PRIu64
             ",\"rx\":%" PRIu64 ",\"lost\":%" PRIu64 ",\"coalesced\":%" PRIu64 ",\"overflow\":%" PRIu64 ",\"stale_transitions\":%" PRIu64
             ",\"stale\":%s,\"rx_rate\":%.1f,\"tx_rate\":%.1f}",
             i ? "," : "", d.name, ss.writes.load(), ss.write_errors.load(), ss.tx.load(), ss.rx.load(),
             ss.lost.load(), ss.coalesced.load(), ss.overflow.load(), ss.stale_transitions.load(), stale ? "true" : "false",
             before ? Rate(before->sig_rx[i], now.sig_rx[i], secs) : 0.0,
             before ? Rate(before->sig_tx[i], now.sig_tx[i], secs) : 0.0);
    }
    printf("]}\n");
    fflush(stdout);
    return;
  }
  printf("node %s: ccommd %s (generation %u)\n", h->node_name, daemon ? "alive" : "NOT RUNNING",
         h->generation.load());
  printf("daemon:");
  for (uint32_t i = 0; i < st::kDaemonCounterCount; ++i) {
    uint64_t v = h->daemon_counters[i].load();
    if (v || i < 3) printf(" %s=%" PRIu64, kCounterNames[i], v);
  }
  printf("\n\n%-12s %-5s %10s %10s %8s %9s %10s %12s %8s\n", "PEER", "ALIVE", "FRAMES_RX", "FRAMES_TX", "LOST",
         "REORDERED", "HEARTBEATS", "LAST_RX_MS", "RX/S");
  for (uint32_t p = 0; p < s.node_count(); ++p) {
    if (p == h->node_id) continue;
    const st::PeerStats& ps = s.peer(p);
    if (!ps.frames_rx.load() && !ps.frames_tx.load()) continue;
    uint64_t last = ps.last_rx_ns.load();
    printf("%-12s %-5s %10" PRIu64 " %10" PRIu64 " %8" PRIu64 " %9" PRIu64 " %10" PRIu64 " %12.1f %8.0f\n",
           s.node_name(p), ps.alive.load() ? "yes" : "NO", ps.frames_rx.load(), ps.frames_tx.load(),
           ps.frames_lost.load(), ps.frames_reordered.load(), ps.heartbeats_rx.load(),
           last ? static_cast<double>(Age(mono, last)) / 1e6 : -1.0,
           before ? Rate(before->peer_rx[p], now.peer_rx[p], secs) : 0.0);
  }
  printf("\n%-24s %10s %10s %10s %8s %8s %6s %6s %8s %8s\n", "SIGNAL", "WRITES", "TX", "RX", "LOST", "OVERFLOW",
         "STALE", "->STL", "RX/S", "TX/S");
  for (uint32_t i = 0; i < s.signal_count(); ++i) {
    const st::SignalStats& ss = s.stats(i);
    const st::SignalDirectoryEntry& d = s.dir(i);
    uint64_t last = ss.last_rx_ns.load();
    const char* stale = "-";
    if ((d.flags & st::kSigConsumedHere) && d.stale_after_ms)
      stale = (!last || Age(mono, last) > uint64_t{d.stale_after_ms} * 1000000) ? "yes" : "no";
    printf("%-24s %10" PRIu64 " %10" PRIu64 " %10" PRIu64 " %8" PRIu64 " %8" PRIu64 " %6s %6" PRIu64
           " %8.0f %8.0f\n",
           d.name, ss.writes.load(), ss.tx.load(), ss.rx.load(), ss.lost.load(), ss.overflow.load(), stale,
           ss.stale_transitions.load(), before ? Rate(before->sig_rx[i], now.sig_rx[i], secs) : 0.0,
           before ? Rate(before->sig_tx[i], now.sig_tx[i], secs) : 0.0);
  }
  fflush(stdout);
}

}  // namespace

int CmdStats(ccomm_client* c, const char*, int argc, char** argv) {
  bool json = false;
  double watch = 0;
  static const struct option kLong[] = {{"json", no_argument, nullptr, 'j'},
                                        {"watch", required_argument, nullptr, 'w'},
                                        {nullptr, 0, nullptr, 0}};
  optind = 0;  // 0: GNU getopt fully re-initialises (1 keeps stale permutation state)
  int ch;
  while ((ch = getopt_long(argc, argv, "jw:", kLong, nullptr)) != -1) {
    if (ch == 'j') json = true;
    else if (ch == 'w') watch = strtod(optarg, nullptr);
    else return 2;
  }
  st::Segment seg;
  if (seg.Open(st::SegmentName(ccomm_node_name(c))) != 0) {
    fprintf(stderr, "ccomm stats: cannot map the segment\n");
    return 1;
  }
  Snapshot before = Take(seg);
  if (watch <= 0) {
    // One-shot: measure rates over a short window so RX/S means something.
    usleep(200000);
    Print(seg, &before, Take(seg), json);
    return 0;
  }
  for (;;) {
    struct timespec ts = {static_cast<time_t>(watch), static_cast<long>((watch - static_cast<double>(static_cast<time_t>(watch))) * 1e9)};
    if (nanosleep(&ts, nullptr) != 0) break;
    Snapshot now = Take(seg);
    if (!json) printf("\033[H\033[J");
    Print(seg, &before, now, json);
    before = now;
  }
  return 0;
}
