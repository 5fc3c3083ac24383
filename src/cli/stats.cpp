// SPDX-License-Identifier: Apache-2.0
// `ccomm stats`: the counters ccommd and the clients keep, through the public API.
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <vector>

#include "ccomm/ccomm.h"
#include "cli/values.h"
#include "common/public/platform_app.h"

namespace {

// Everything `stats` prints, read through the public introspection API at one instant.
struct Snapshot {
  int64_t t = 0;
  int alive = 0;
  uint32_t generation = 0;
  std::vector<const char*> counter_names;
  std::vector<uint64_t> counters;
  std::vector<ccomm_peer_stats> peers;
  std::vector<ccomm_peer_clock> clocks;  // per node, as peers
  ccomm_clock_state clock{};              // this board's synchronisation (ptp4l)
  std::vector<ccomm_signal_stats> sigs;
  std::vector<ccomm_signal_desc> descs;
};

Snapshot Take(ccomm_client* c) {
  Snapshot n;
  n.t = ccomm_now();
  n.alive = ccomm_daemon_alive(c);
  n.generation = ccomm_daemon_generation(c);
  ccomm_get_clock_state(c, &n.clock);
  const char* name;
  uint64_t value;
  for (int i = 0; ccomm_get_daemon_counter(c, i, &name, &value) == 0; ++i) {
    n.counter_names.push_back(name);
    n.counters.push_back(value);
  }
  for (int p = 0; p < ccomm_node_count(c); ++p) {
    ccomm_peer_stats ps;
    ccomm_get_peer_stats(c, p, &ps);
    n.peers.push_back(ps);
    ccomm_peer_clock pc;
    ccomm_get_peer_clock(c, p, &pc);
    n.clocks.push_back(pc);
  }
  for (int i = 0; i < ccomm_signal_count(c); ++i) {
    ccomm_signal_stats ss;
    ccomm_signal_desc d;
    ccomm_get_signal_stats(c, i, &ss);
    ccomm_describe(c, i, &d);
    n.sigs.push_back(ss);
    n.descs.push_back(d);
  }
  return n;
}

// This board's CLOCK_REALTIME minus its CLOCK_MONOTONIC (ccomm_now's clock, which frames'
// send times and the peers' clock floors are on), the monotonic clock read on both sides:
// what maps the floors to real time (ccomm deploy's clock offsets between boards).
int64_t RealtimeOffsetNs() {
  const uint64_t m0 = ccomm::platform::MonotonicNs();
  // std::chrono's system_clock: CLOCK_REALTIME on Linux, the system time on Windows.
  const int64_t rt = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::system_clock::now().time_since_epoch()).count();
  const uint64_t m1 = ccomm::platform::MonotonicNs();
  return rt - static_cast<int64_t>(m0 + (m1 - m0) / 2);
}

double Rate(uint64_t a, uint64_t b, double secs) { return secs > 0 ? static_cast<double>(b - a) / secs : 0; }
double AgeMs(int64_t age_ns) { return age_ns < 0 ? -1.0 : static_cast<double>(age_ns) / 1e6; }

void Print(ccomm_client* c, const Snapshot* before, const Snapshot& now, bool json) {
  const double secs = before ? static_cast<double>(now.t - before->t) / 1e9 : 0;
  const char* node = ccomm_node_name(c);
  if (json) {
    printf("{\"node\":\"%s\",\"daemon_alive\":%s,\"generation\":%u,\"counters\":{", node,
           now.alive ? "true" : "false", now.generation);
    for (size_t i = 0; i < now.counters.size(); ++i)
      printf("%s\"%s\":%" PRIu64, i ? "," : "", now.counter_names[i], now.counters[i]);
    printf("},\"clock\":{\"state\":\"%s\",\"port_state\":%d,\"offset_ns\":%" PRId64
           ",\"path_delay_ns\":%" PRId64 "}", ccomm_clock_state_name(now.clock.state), now.clock.port_state,
           now.clock.offset_ns, now.clock.path_delay_ns);
    printf(",\"realtime_offset_ns\":%" PRId64, RealtimeOffsetNs());
    printf(",\"peers\":[");
    bool first = true;
    for (const ccomm_peer_stats& ps : now.peers) {
      if (ps.is_self) continue;
      printf("%s{\"name\":\"%s\",\"alive\":%s,\"frames_rx\":%" PRIu64 ",\"frames_tx\":%" PRIu64
             ",\"frames_lost\":%" PRIu64 ",\"frames_reordered\":%" PRIu64 ",\"heartbeats_rx\":%" PRIu64
             ",\"down_transitions\":%" PRIu64 ",\"last_rx_age_ms\":%.1f",
             first ? "" : ",", ps.name, ps.alive ? "true" : "false", ps.frames_rx, ps.frames_tx, ps.frames_lost,
             ps.frames_reordered, ps.heartbeats_rx, ps.down_transitions, AgeMs(ps.last_rx_age_ns));
      const ccomm_peer_clock& pc = now.clocks[static_cast<size_t>(&ps - now.peers.data())];
      printf(",\"clock\":{\"known\":%s,\"offset_floor_ns\":%" PRId64 ",\"queue_delay_ms\":%.3f"
             ",\"queue_delay_max_ms\":%.3f,\"frames_delayed\":%" PRIu64 "}}",
             pc.known ? "true" : "false", pc.offset_floor_ns, static_cast<double>(pc.queue_delay_ns) / 1e6,
             static_cast<double>(pc.queue_delay_max_ns) / 1e6, pc.frames_delayed);
      first = false;
    }
    printf("],\"signals\":[");
    for (size_t i = 0; i < now.sigs.size(); ++i) {
      const ccomm_signal_stats& ss = now.sigs[i];
      printf("%s{\"name\":\"%s\",\"writes\":%" PRIu64 ",\"write_errors\":%" PRIu64 ",\"tx\":%" PRIu64
             ",\"rx\":%" PRIu64 ",\"lost\":%" PRIu64 ",\"coalesced\":%" PRIu64 ",\"overflow\":%" PRIu64
             ",\"stale_transitions\":%" PRIu64 ",\"corrupt\":%" PRIu64 ",\"fragments_refused\":%" PRIu64
             ",\"values_incomplete\":%" PRIu64 ",\"stale\":%s,\"rx_rate\":%.1f,\"tx_rate\":%.1f}",
             i ? "," : "", now.descs[i].name, ss.writes, ss.write_errors, ss.tx, ss.rx, ss.lost, ss.coalesced,
             ss.overflow, ss.stale_transitions, ss.corrupt, ss.fragments_refused, ss.values_incomplete,
             ss.stale ? "true" : "false",
             before ? Rate(before->sigs[i].rx, ss.rx, secs) : 0.0, before ? Rate(before->sigs[i].tx, ss.tx, secs) : 0.0);
    }
    printf("]}\n");
    fflush(stdout);
    return;
  }
  printf("node %s: ccommd %s (generation %u)\n", node, now.alive ? "alive" : "NOT RUNNING", now.generation);
  if (now.clock.state == CCOMM_CLOCK_NONE)
    printf("clock: none (no ptp4l answers): ages are local\n");
  else
    printf("clock: %s (ptp4l port state %d, offset %" PRId64 " ns)%s\n", ccomm_clock_state_name(now.clock.state),
           now.clock.port_state, now.clock.offset_ns,
           "; ages are local");
  for (size_t i = 0; i < now.counters.size(); ++i) {  // send on the cycle (daemon/engine/send_cycle.h, LaunchMode)
    static const char* const kLaunch[] = {"off", "launch times (SO_TXTIME, ETF qdisc)",
                                          "sleeps until each instant (launch_time=\"sleep\")",
                                          "sleeps until each instant (no SO_TXTIME on this platform)",
                                          "sleeps until each instant (the socket refused SO_TXTIME)",
                                          "sleeps until each instant (no ETF qdisc for its frames)"};
    if (strcmp(now.counter_names[i], "cycle_launch") == 0 && now.counters[i] && now.counters[i] < 6)
      printf("send cycle: %s\n", kLaunch[now.counters[i]]);
  }
  printf("daemon:");
  for (size_t i = 0; i < now.counters.size(); ++i) {
    if (now.counters[i] || i < 3) printf(" %s=%" PRIu64, now.counter_names[i], now.counters[i]);
  }
  printf("\n\n%-12s %-5s %10s %10s %8s %9s %10s %12s %8s\n", "PEER", "ALIVE", "FRAMES_RX", "FRAMES_TX", "LOST",
         "REORDERED", "HEARTBEATS", "LAST_RX_MS", "RX/S");
  for (size_t p = 0; p < now.peers.size(); ++p) {
    const ccomm_peer_stats& ps = now.peers[p];
    if (ps.is_self || (!ps.frames_rx && !ps.frames_tx)) continue;
    printf("%-12s %-5s %10" PRIu64 " %10" PRIu64 " %8" PRIu64 " %9" PRIu64 " %10" PRIu64 " %12.1f %8.0f\n", ps.name,
           ps.alive ? "yes" : "NO", ps.frames_rx, ps.frames_tx, ps.frames_lost, ps.frames_reordered, ps.heartbeats_rx,
           AgeMs(ps.last_rx_age_ns), before ? Rate(before->peers[p].frames_rx, ps.frames_rx, secs) : 0.0);
  }
  // Peers' clocks as bounded from their frames (ccomm_get_peer_clock): what ages include.
  bool clock_header = false;
  for (size_t p = 0; p < now.peers.size(); ++p) {
    const ccomm_peer_clock& pc = now.clocks[p];
    if (now.peers[p].is_self || !pc.known) continue;
    if (!clock_header) {
      printf("\npeer clocks, from their frames: ages are local, arrival on this node plus the frame's\n"
             "queueing delay beyond the fastest frame of the last 2-4 s\n%-12s %16s %14s %14s %10s\n", "PEER",
             "OFFSET_FLOOR_MS", "QUEUE_DELAY_MS", "MAX_DELAY_MS", "DELAYED");
      clock_header = true;
    }
    printf("%-12s %16.3f %14.3f %14.3f %10" PRIu64 "\n", now.peers[p].name,
           static_cast<double>(pc.offset_floor_ns) / 1e6, static_cast<double>(pc.queue_delay_ns) / 1e6,
           static_cast<double>(pc.queue_delay_max_ns) / 1e6, pc.frames_delayed);
  }
  printf("\n%-24s %10s %10s %10s %8s %8s %6s %6s %8s %8s\n", "SIGNAL", "WRITES", "TX", "RX", "LOST", "OVERFLOW",
         "STALE", "->STL", "RX/S", "TX/S");
  for (size_t i = 0; i < now.sigs.size(); ++i) {
    const ccomm_signal_stats& ss = now.sigs[i];
    const ccomm_signal_desc& d = now.descs[i];
    const char* stale = (d.consumed_here && d.stale_after_ms) ? (ss.stale ? "yes" : "no") : "-";
    printf("%-24s %10" PRIu64 " %10" PRIu64 " %10" PRIu64 " %8" PRIu64 " %8" PRIu64 " %6s %6" PRIu64 " %8.0f %8.0f\n",
           d.name, ss.writes, ss.tx, ss.rx, ss.lost, ss.overflow, stale, ss.stale_transitions,
           before ? Rate(before->sigs[i].rx, ss.rx, secs) : 0.0, before ? Rate(before->sigs[i].tx, ss.tx, secs) : 0.0);
  }
  for (size_t i = 0; i < now.sigs.size(); ++i) {  // large values only, and only when it matters
    const ccomm_signal_stats& ss = now.sigs[i];
    if (ss.fragments_refused || ss.values_incomplete)
      printf("%s: fragments_refused=%" PRIu64 " values_incomplete=%" PRIu64 "\n", now.descs[i].name,
             ss.fragments_refused, ss.values_incomplete);
  }
  fflush(stdout);
}

}  // namespace

int CmdStatsAll(ccomm_client* c, bool json, double watch);  // stats_all.cpp

namespace {
// A ccommd restarted with another configuration retires the segment: its counters stay
// frozen where they were, so --watch stops and says so (ccomm(1), EXIT STATUS 1). The
// library's wait reports the retirement (also for a node without signals).
bool Retired(ccomm_client* c) { return ccomm_wait(c, 0) == CCOMM_E_RETIRED; }
}  // namespace

int CmdStats(ccomm_client* c, const char*, int argc, char** argv) {
  bool json = false, all = false;
  double watch = 0;
  static const struct option kLong[] = {{"json", no_argument, nullptr, 'j'},
                                        {"all", no_argument, nullptr, 'a'},
                                        {"watch", required_argument, nullptr, 'w'},
                                        {nullptr, 0, nullptr, 0}};
  optind = 0;  // 0: GNU getopt fully re-initialises (1 keeps stale permutation state)
  int ch;
  while ((ch = getopt_long(argc, argv, "ajw:", kLong, nullptr)) != -1) {
    if (ch == 'j') json = true;
    else if (ch == 'a') all = true;
    else if (ch == 'w' && ccomm::cli::ParseOptionNumber(optarg, false, false, &watch)) continue;
    else if (ch == 'w') {
      fprintf(stderr, "ccomm stats: --watch needs a positive number of seconds, not '%s'\n", optarg);
      return 2;
    }
    else return 2;
  }
  if (optind < argc) {
    fprintf(stderr, "ccomm stats: unexpected argument '%s'\n", argv[optind]);
    return 2;
  }
  if (all) return CmdStatsAll(c, json, watch);
  Snapshot before = Take(c);
  if (watch <= 0) {
    // One-shot: measure rates over a short window so RX/S means something.
    ccomm::platform::SleepNsInterruptible(200000000u);
    Print(c, &before, Take(c), json);
    return 0;
  }
  for (;;) {
    if (ccomm::platform::SleepNsInterruptible(ccomm::cli::WatchPeriodNs(watch)) != 0) break;
    if (Retired(c)) {
      fprintf(stderr, "ccomm stats: %s\n", ccomm_strerror(CCOMM_E_RETIRED));
      return 1;
    }
    Snapshot now = Take(c);
    if (!json) printf("\033[H\033[J");
    Print(c, &before, now, json);
    before = now;
  }
  return 0;
}
