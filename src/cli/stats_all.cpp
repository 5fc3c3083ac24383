// SPDX-License-Identifier: Apache-2.0
// `ccomm stats --all`: the system view (every node as this board's ccommd heard it from
// the node summaries; libccomm's ccomm_view_*), as a table or one JSON object per snapshot.
#include <inttypes.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include <string>

#include "ccomm/ccomm.h"
#include "cli/values.h"
#include "common/public/platform_app.h"
#include "tools/json_text.h"

namespace {

// JSON string body: names are XML names (no quotes), but escape anyway.
std::string Json(const char* s) { return ccomm::app::JsonText(s); }

double Ms(int64_t ns) { return ns < 0 ? -1.0 : static_cast<double>(ns) / 1e6; }

// Names of the nodes set in `mask`, comma-separated.
std::string PeerNames(ccomm_client* c, uint64_t mask, bool json) {
  std::string out;
  for (int p = 0; p < ccomm_node_count(c) && p < 64; ++p) {
    if (!(mask >> p & 1u)) continue;
    ccomm_peer_stats ps;
    if (ccomm_get_peer_stats(c, p, &ps) != 0) continue;
    if (!out.empty()) out += ",";
    out += json ? "\"" + Json(ps.name) + "\"" : std::string(ps.name);
  }
  return out.empty() && !json ? "-" : out;
}

// A node's clock as one word: its state, and its error bound when it has one.
std::string ClockText(const ccomm_view_node& vn) {
  char buf[48];
  if (vn.clock_error_ns < 0) snprintf(buf, sizeof buf, "%s", ccomm_clock_state_name(vn.clock_state));
  else if (vn.clock_error_ns < 10000) snprintf(buf, sizeof buf, "%s+-%" PRId64 "ns", ccomm_clock_state_name(vn.clock_state), vn.clock_error_ns);
  else snprintf(buf, sizeof buf, "%s+-%.0fus", ccomm_clock_state_name(vn.clock_state), static_cast<double>(vn.clock_error_ns) / 1e3);
  return buf;
}

std::string ClockJson(const ccomm_view_node& vn) {
  char buf[80];
  if (vn.clock_error_ns < 0) snprintf(buf, sizeof buf, "{\"state\":\"%s\",\"error_ns\":null}", ccomm_clock_state_name(vn.clock_state));
  else snprintf(buf, sizeof buf, "{\"state\":\"%s\",\"error_ns\":%" PRId64 "}", ccomm_clock_state_name(vn.clock_state), vn.clock_error_ns);
  return buf;
}

void PrintJson(ccomm_client* c, ccomm_view* v) {
  ccomm_view_counters vc;
  ccomm_view_get_counters(v, &vc);
  printf("{\"node\":\"%s\",\"summary_ms\":%u,\"summaries\":{\"tx\":%" PRIu64 ",\"rx\":%" PRIu64
         ",\"refused\":%" PRIu64 ",\"old\":%" PRIu64 ",\"send_errors\":%" PRIu64 "},\"nodes\":[",
         Json(ccomm_node_name(c)).c_str(), vc.summary_ms, vc.summaries_tx, vc.summaries_rx, vc.summaries_refused,
         vc.summaries_old, vc.summaries_send_errors);
  bool first_node = true;
  for (int n = 0; n < ccomm_node_count(c); ++n) {
    ccomm_view_node vn;
    if (ccomm_view_get_node(v, n, &vn) != 0) continue;  // busy for 50 ms: left out of this snapshot
    printf("%s{\"name\":\"%s\",\"self\":%s,\"reported\":%s,\"alive\":%s,\"age_ms\":%.1f,\"timeout_ms\":%.0f,"
           "\"uptime_s\":%.3f,\"peers_alive\":[%s],\"frames_rx\":%" PRIu64 ",\"frames_tx\":%" PRIu64
           ",\"frames_bad\":%" PRIu64 ",\"frames_lost\":%" PRIu64 ",\"socket_drops\":%" PRIu64
           ",\"cycle_ms\":%u,\"summaries\":%" PRIu64 ",\"clock\":%s,\"signals\":[",
           first_node ? "" : ",", Json(vn.name).c_str(), vn.is_self ? "true" : "false", vn.reported ? "true" : "false",
           vn.alive ? "true" : "false", Ms(vn.age_ns), Ms(vn.timeout_ns), static_cast<double>(vn.uptime_ns) / 1e9,
           PeerNames(c, vn.peers_alive, true).c_str(), vn.frames_rx, vn.frames_tx, vn.frames_bad, vn.frames_lost,
           vn.socket_drops, vn.cycle_ms, vn.summaries, ClockJson(vn).c_str());
    first_node = false;
    bool first = true;
    for (int s = 0; s < ccomm_signal_count(c); ++s) {
      ccomm_view_signal vs;
      if (ccomm_view_get_signal(v, n, s, &vs) != 0) continue;
      printf("%s{\"name\":\"%s\",\"role\":\"%s\",\"rate\":%.3f,\"lost\":%" PRIu64 ",\"stale\":%s,\"age_ms\":%.1f}",
             first ? "" : ",", Json(vs.name).c_str(), vs.role == CCOMM_ROLE_PRODUCER ? "producer" : "consumer",
             vs.rate, vs.lost, vs.stale ? "true" : "false", Ms(vs.age_ns));
      first = false;
    }
    printf("]}");
  }
  printf("]}\n");
  fflush(stdout);
}

void PrintTable(ccomm_client* c, ccomm_view* v) {
  ccomm_view_counters vc;
  ccomm_view_get_counters(v, &vc);
  printf("system view from node %s (summaries every %u ms; tx=%" PRIu64 " rx=%" PRIu64 " refused=%" PRIu64 ")\n\n",
         ccomm_node_name(c), vc.summary_ms, vc.summaries_tx, vc.summaries_rx, vc.summaries_refused);
  printf("%-12s %-5s %9s %10s %10s %10s %8s %8s %-18s %s\n", "NODE", "ALIVE", "LAST_MS", "UPTIME_S", "FRAMES_RX",
         "FRAMES_TX", "BAD", "LOST", "CLOCK", "HEARS");
  for (int n = 0; n < ccomm_node_count(c); ++n) {
    ccomm_view_node vn;
    if (ccomm_view_get_node(v, n, &vn) != 0) continue;
    if (!vn.reported) {
      printf("%-12s %-5s %9s  (no summary received: not running, unreachable, or summary_ms=\"0\")\n", vn.name,
             "?", "-");
      continue;
    }
    printf("%-12s %-5s %9.0f %10.1f %10" PRIu64 " %10" PRIu64 " %8" PRIu64 " %8" PRIu64 " %-18s %s\n", vn.name,
           vn.alive ? "yes" : "NO", Ms(vn.age_ns), static_cast<double>(vn.uptime_ns) / 1e9, vn.frames_rx,
           vn.frames_tx, vn.frames_bad, vn.frames_lost, ClockText(vn).c_str(), PeerNames(c, vn.peers_alive, false).c_str());
  }
  printf("\n%-12s %-24s %-8s %10s %8s %-5s %10s\n", "NODE", "SIGNAL", "ROLE", "RATE/S", "LOST", "STALE", "AGE_MS");
  for (int n = 0; n < ccomm_node_count(c); ++n) {
    ccomm_view_node vn;
    if (ccomm_view_get_node(v, n, &vn) != 0 || !vn.reported) continue;
    for (int s = 0; s < ccomm_signal_count(c); ++s) {
      ccomm_view_signal vs;
      if (ccomm_view_get_signal(v, n, s, &vs) != 0) continue;
      char age[32];
      if (vs.age_ns < 0) snprintf(age, sizeof age, "never");
      else snprintf(age, sizeof age, "%.0f", Ms(vs.age_ns));
      printf("%-12s %-24s %-8s %10.1f %8" PRIu64 " %-5s %10s\n", vn.name, vs.name,
             vs.role == CCOMM_ROLE_PRODUCER ? "producer" : "consumer", vs.rate, vs.lost, vs.stale ? "yes" : "no",
             age);
    }
  }
  fflush(stdout);
}

}  // namespace

// Called by CmdStats for --all; `watch` > 0 repeats every `watch` seconds.
int CmdStatsAll(ccomm_client* c, bool json, double watch) {
  ccomm_view* v = nullptr;
  int r = ccomm_view_open(c, &v);
  if (r != 0) {
    fprintf(stderr, "ccomm stats --all: no system view for node '%s': %s (%s)\n", ccomm_node_name(c),
            ccomm_strerror(r),
            r == CCOMM_E_NOENT ? "is a ccommd with node summaries running for this node?"
                               : "ccommd and this ccomm come from different versions, or ccommd restarted with "
                                 "another configuration: retry");
    return 1;
  }
  for (;;) {
    if (watch > 0 && !json) printf("\033[H\033[J");
    if (json) PrintJson(c, v);
    else PrintTable(c, v);
    if (watch <= 0) break;
    if (ccomm::platform::SleepNsInterruptible(ccomm::cli::WatchPeriodNs(watch)) != 0) break;
  }
  ccomm_view_close(v);
  return 0;
}
