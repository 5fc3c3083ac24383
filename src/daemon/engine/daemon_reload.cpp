// SPDX-License-Identifier: Apache-2.0
// Reload (daemon.h, docs/usage.md "Reload"): a new file replaces the running configuration
// in this process. The I/O threads are stopped and started again around it (main.cpp), so
// the send and receive loops never look for a new configuration: nothing is added to
// their hot paths, and what they read is handed over by pthread_join / pthread_create.
// The socket stays open meanwhile (frames that arrive queue in it), so does the segment
// when its layout is the same.
#include <stdio.h>
#include <string.h>

#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "daemon/engine/segment_builder.h"

namespace ccomm {
namespace {

const char* KindName(TransportKind k) { return k == TransportKind::kRaw ? "raw" : "udp"; }

std::string MacText(const NodeConfig& n) {
  if (!n.has_mac) return "none";
  char b[24];
  snprintf(b, sizeof b, "%02x:%02x:%02x:%02x:%02x:%02x", n.mac[0], n.mac[1], n.mac[2], n.mac[3], n.mac[4], n.mac[5]);
  return b;
}

}  // namespace

std::string Daemon::ReloadRefusal(const SystemConfig& next, uint32_t node_id) const {
  const SystemConfig& cur = *cfg_;
  const NodeConfig& was = cur.nodes[self_];
  const NodeConfig& now = next.nodes[node_id];
  std::string out;
  auto refuse = [&](int line, const std::string& what) {
    // <network> has no line of its own in SystemConfig: the file alone then.
    out += next.path + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": error: " + what +
           " cannot change on a reload (restart ccommd to apply it: systemctl restart ccommd)\n";
  };
  auto differs = [&](const char* what, const std::string& a, const std::string& b, int line) {
    if (a != b) refuse(line, std::string(what) + " (" + a + " -> " + b + ")");
  };
  // The socket was opened from these, with a capability ccommd no longer has.
  const TransportKind kw = opt_.force_udp ? TransportKind::kUdp : was.transport;
  const TransportKind kn = opt_.force_udp ? TransportKind::kUdp : now.transport;
  const std::string node = "node '" + now.name + "': ";
  differs((node + "transport").c_str(), KindName(kw), KindName(kn), now.line);
  differs((node + "interface").c_str(), was.interface, now.interface, now.line);
  differs((node + "ip").c_str(), was.ip, now.ip, now.line);
  differs((node + "mac").c_str(), MacText(was), MacText(now), now.line);
  differs((node + "multicast").c_str(), was.multicast, now.multicast, now.line);
  differs("<network> ethertype", std::to_string(cur.network.ethertype), std::to_string(next.network.ethertype), 0);
  differs("<network> udp_port", std::to_string(cur.network.udp_port), std::to_string(next.network.udp_port), 0);
  differs("<network> auth_key_file", cur.network.auth_key_file, next.network.auth_key_file, 0);
  differs("<network> fanout", cur.network.fanout == Fanout::kMulticast ? "multicast" : "unicast",
          next.network.fanout == Fanout::kMulticast ? "multicast" : "unicast", 0);
  if (memcmp(cur.network.multicast_base, next.network.multicast_base, 4) != 0) refuse(0, "<network> multicast base");
  // A node without peers has no socket; one with multicast fan-out joined its groups.
  PreparedSignals route;
  route.Route(next, node_id);
  if (route.exchanges_any() != table_.exchanges_any())
    refuse(now.line, node + (route.exchanges_any() ? "exchanging signals (it has no socket)"
                                                   : "exchanging no signals any more (its socket)"));
  if (table_.multicast() || route.multicast()) {
    bool same = cur.nodes.size() == next.nodes.size();
    for (uint32_t p = 0; same && p < next.nodes.size(); ++p) same = route.receives_from(p) == table_.receives_from(p);
    if (!same) refuse(now.line, node + "the peers of multicast fan-out (the joined groups)");
  }
  // Send on the cycle: set up on the socket at start (SO_TXTIME needs CAP_NET_ADMIN then).
  const RealtimeConfig &rw = was.realtime, &rn = now.realtime;
  if (rw.send_cycle_us != rn.send_cycle_us || rw.send_phase_us != rn.send_phase_us ||
      rw.send_lead_us != rn.send_lead_us || rw.launch_time != rn.launch_time)
    refuse(rn.send_cycle_line ? rn.send_cycle_line : now.line, node + "<realtime> send_cycle_us/send_phase_us/"
           "send_lead_us/launch_time");
  return out;
}

int Daemon::Reconfigure(const SystemConfig& next, uint32_t node_id, std::string* error) {
  const size_t old_nodes = cfg_ ? cfg_->nodes.size() : 0, old_signals = cfg_ ? cfg_->signals.size() : 0;
  cfg_ = &next;
  self_ = node_id;
  // <clock socket=> names ptp4l's socket unless --ptp-socket did (as main() at start).
  const std::string ptp = opt_.ptp_socket_given ? opt_.ptp_socket
                          : next.clock.present  ? next.clock.socket
                                                : DaemonOptions().ptp_socket;
  supervisor_.Configure(next, node_id, ptp, opt_.ptp_synced_within_ns);
  const NodeConfig& self = next.nodes[node_id];
  const TransportKind kind = opt_.force_udp ? TransportKind::kUdp : self.transport;
  table_.Route(next, node_id);
  std::vector<PeerAddress> groups;  // joined at start; ReloadRefusal keeps them the same
  int r = send_.OpenStreams(next, node_id, kind, opt_.force_udp, &groups, error);
  if (r != 0) return r;
  const std::string name = store::SegmentName(self.name);
  const std::string fit = SegmentFitProblem(next, node_id, name);
  if (!fit.empty()) {
    *error = fit;
    return -ENOSPC;
  }
  r = CreateOrAdoptSegment(&segment_, next, node_id, name, gid_, &adopted_, error);
  if (r != 0) return r;
  table_.Resolve(segment_, auth_.enabled());
  supervisor_.Prepare(adopted_, /*reload=*/true);
  const bool same_shape = adopted_ && old_nodes == next.nodes.size() && old_signals == next.signals.size();
  send_.Prepare(adopted_, same_shape);
  receive_.Prepare(next, node_id, kind, opt_.recv_timeout_ms, same_shape);
  view_.Stop();
  r = view_.Start(next, node_id, kind, opt_.force_udp, &segment_, &transport_, &auth_, gid_, error);
  if (r != 0) return r;
  // The send cycle (handoffs_.send_cycle) stays as configured at start: ReloadRefusal.
  StartRunning();
  return 0;
}

}  // namespace ccomm
