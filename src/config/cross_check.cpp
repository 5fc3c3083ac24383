// SPDX-License-Identifier: Apache-2.0
// Checks across elements: unique names and addresses, producers and consumers that
// exist, transports that match.

#include <algorithm>
#include <cstring>

#include "common/platform.h"
#include "config/parser.h"

namespace ccomm {
namespace config_detail {

void Parser::CrossCheck(SystemConfig* cfg) {
  std::vector<std::string> node_names;
  for (size_t i = 0; i < cfg->nodes.size(); ++i) {
    const NodeConfig& n = cfg->nodes[i];
    node_names.push_back(n.name);
    for (size_t j = 0; j < i; ++j) {
      const NodeConfig& m = cfg->nodes[j];
      if (!n.name.empty() && n.name == m.name) {
        Err(n.line, "duplicate node name " + Quote(n.name) + " (first defined at line " +
                        std::to_string(m.line) + ")");
        break;
      }
      if (!n.ip.empty() && n.ip == m.ip)
        Err(n.line, "node " + Quote(n.name) + " has the same ip " + n.ip + " as node " +
                        Quote(m.name) + " (line " + std::to_string(m.line) + ")");
      if (n.has_mac && m.has_mac && std::memcmp(n.mac, m.mac, 6) == 0)
        Err(n.line, "node " + Quote(n.name) + " has the same mac as node " + Quote(m.name) +
                        " (line " + std::to_string(m.line) + ")");
    }
  }
  // Send on the cycle: the send thread waits up to the lead for a round's instant, and
  // heartbeats wait with it; a lead of a heartbeat or more would let peers time it out.
  for (const NodeConfig& n : cfg->nodes) {
    const RealtimeConfig& rt = n.realtime;
    if (rt.send_lead_line && uint64_t{rt.send_lead_us} >= uint64_t{cfg->network.heartbeat_ms} * 1000)
      Err(rt.send_lead_line, "send_lead_us " + std::to_string(rt.send_lead_us) + " is not below heartbeat_ms " +
                                 std::to_string(cfg->network.heartbeat_ms) +
                                 ": the send thread waits up to the lead for each round, heartbeats too, "
                                 "so peers would report node " + Quote(n.name) + " lost");
  }
  std::string known = cfg->nodes.empty()       ? " (no nodes defined)"
                      : cfg->nodes.size() <= 8 ? " (nodes: " + Join(node_names, ", ") + ")"
                                               : "";
  auto unknown_node = [&](const std::string& what, const std::string& name) {
    std::string hint = Suggest(name, node_names);
    return "unknown " + what + " node " + Quote(name) + (hint.empty() ? known : hint);
  };

  // Signal names: hash lookups are not needed at this size (<= 4096, once at start-up),
  // but a quadratic scan over 4096 would be 8M compares; sort indices instead.
  std::vector<size_t> order(cfg->signals.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return cfg->signals[a].name < cfg->signals[b].name;
  });
  for (size_t k = 1; k < order.size(); ++k) {
    const SignalConfig& first = cfg->signals[order[k - 1]];
    const SignalConfig& s = cfg->signals[order[k]];
    if (!s.name.empty() && s.name == first.name) {
      // Report against the first definition of the run (the stable sort keeps file order).
      size_t r = k - 1;
      while (r > 0 && cfg->signals[order[r - 1]].name == s.name) --r;
      Err(s.line, "duplicate signal name " + Quote(s.name) + " (first defined at line " +
                      std::to_string(cfg->signals[order[r]].line) + ")");
    }
  }

  std::vector<std::pair<uint32_t, uint32_t>> mixed;  // node pairs already reported
  // ccommd opens one transport, its own node's, and reaches every peer with it
  // (daemon/net/transport.h), so nodes that exchange signals must agree on it.
  // Reported once per pair of nodes.
  auto check_transport = [&](const SignalConfig& s, int producer, uint32_t c, int line) {
    if (producer < 0) return;
    const NodeConfig& pn = cfg->nodes[static_cast<size_t>(producer)];
    const NodeConfig& cn = cfg->nodes[c];
    if (pn.transport == cn.transport) return;
    std::pair<uint32_t, uint32_t> pair(std::min<uint32_t>(producer, c), std::max<uint32_t>(producer, c));
    if (std::find(mixed.begin(), mixed.end(), pair) != mixed.end()) return;
    mixed.push_back(pair);
    auto tname = [](TransportKind k) { return k == TransportKind::kUdp ? "udp" : "raw"; };
    Err(line, "signal " + Quote(s.name) + " goes from " + tname(pn.transport) + " node " +
                  Quote(pn.name) + " to " + tname(cn.transport) + " node " + Quote(cn.name) +
                  "; nodes that exchange signals need the same transport= (ccommd uses " +
                  "one transport for all its peers)");
  };
  for (size_t i = 0; i < cfg->signals.size(); ++i) {
    SignalConfig& s = cfg->signals[i];
    const SignalRefs& r = refs_[i];
    int producer = -1;
    if (r.producer_line) {
      producer = cfg->FindNode(r.producer);
      if (producer < 0)
        Err(r.producer_line, unknown_node("producer", r.producer));
      else
        s.producer = static_cast<uint32_t>(producer);
    }
    for (const auto& [name, line] : r.consumers) {
      int c = cfg->FindNode(name);
      if (c < 0) {
        Err(line, unknown_node("consumer", name));
        continue;
      }
      if (c == producer) {
        Err(line, "producer " + Quote(name) + " listed as a consumer of " + Quote(s.name) +
                      " (apps on the producer's node read it from shared memory already)");
        continue;
      }
      if (std::find(s.consumers.begin(), s.consumers.end(), static_cast<uint32_t>(c)) !=
          s.consumers.end()) {
        Err(line, "consumer " + Quote(name) + " listed twice for " + Quote(s.name));
        continue;
      }
      s.consumers.push_back(static_cast<uint32_t>(c));
      check_transport(s, producer, static_cast<uint32_t>(c), line);
    }
    // Monitor nodes consume every matching signal produced elsewhere, without being
    // listed (recorders, bridges, dashboards); the expanded lists are what is hashed.
    for (uint32_t m = 0; m < cfg->nodes.size(); ++m) {
      const NodeConfig& mn = cfg->nodes[m];
      if (mn.monitor.empty() || static_cast<int>(m) == producer || producer < 0) continue;
      if (std::find(s.consumers.begin(), s.consumers.end(), m) != s.consumers.end()) continue;
      const bool match = std::any_of(mn.monitor.begin(), mn.monitor.end(), [&](const std::string& p) {
        return platform::GlobMatch(p.c_str(), s.name.c_str());
      });
      if (!match) continue;
      s.consumers.push_back(m);
      check_transport(s, producer, m, mn.line);
    }
    // Send on the cycle: a periodic signal leaves on instants of its producer's cycle.
    if (producer >= 0 && s.period_us) {
      const RealtimeConfig& rt = cfg->nodes[static_cast<size_t>(producer)].realtime;
      if (rt.send_cycle_us && s.period_us % rt.send_cycle_us != 0)
        Err(s.line, "period of signal " + Quote(s.name) + " (" + std::to_string(s.period_us) +
                        " us) is not a multiple of its producer " + Quote(cfg->nodes[static_cast<size_t>(producer)].name) +
                        "'s send_cycle_us " + std::to_string(rt.send_cycle_us) + " (line " +
                        std::to_string(rt.send_cycle_line) + ")");
    }
    // stale_by="production" learns whether the producer's clock is synced from its node
    // summaries: without them every value would silently be judged by its arrival.
    if (s.stale_by == StaleBy::kProduction && cfg->network.summary_ms == 0)
      Err(s.line, "stale_by=\"production\" on signal " + Quote(s.name) +
                      " needs node summaries (the producer's clock state travels in them), but "
                      "<network summary_ms=\"0\"> turns them off");
  }
  CrossCheckClock(cfg);
}

}  // namespace config_detail
}  // namespace ccomm
