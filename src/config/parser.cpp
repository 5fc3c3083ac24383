// SPDX-License-Identifier: Apache-2.0
#include "config/parser.h"

#include <algorithm>
#include <cstring>

namespace ccomm {
namespace config_detail {

// Reports text inside an element (everything in this format is an attribute).
void CheckNoText(const Node* parent, Diagnostics* diag) {
  for (const Node* c = parent->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_data && c->type() != rapidxml::node_cdata) continue;
    std::string_view v(c->value(), c->value_size());
    size_t first = v.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos) continue;
    std::string_view shown = v.substr(first, 20);
    size_t nl = shown.find_first_of("\r\n");
    if (nl != std::string_view::npos) shown = shown.substr(0, nl);
    diag->Error(diag->LineOf(c->value() + first),
                "unexpected text " + Quote(shown) + " inside <" + std::string(NameOf(parent)) +
                    "> (settings go in attributes)");
  }
}
void CheckAttributesOnly(const Node* parent, Diagnostics* diag) {
  CheckNoText(parent, diag);
  for (const Node* c = parent->first_node(); c; c = c->next_sibling())
    if (c->type() == rapidxml::node_element)
      diag->Error(diag->LineOf(c->name()), "unknown element <" + std::string(NameOf(c)) + "> in <" +
                                               std::string(NameOf(parent)) + "> (it has attributes only)");
}
bool Parser::Name(const Element& e, const char* what, std::string* out) {
  const AttrValue* a = e.Get("name");
  if (a == nullptr) {
    if (!e.Has("name"))
      Err(e.line(), "<" + std::string(e.tag()) + "> without name=");
    return false;
  }
  const std::string& v = a->value;
  std::string w = what;
  if (v.empty()) {
    Err(a->line, "empty " + w + " name");
    return false;
  }
  for (char c : v) {
    bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
              c == '_' || c == '.' || c == '-';
    if (!ok) {
      std::string ch = (static_cast<unsigned char>(c) & 0x80) ? std::string("non-ASCII character")
                                                              : "invalid character " +
                                                                    Quote(std::string_view(&c, 1));
      Err(a->line, ch + " in " + w + " name " + Quote(v) + " (allowed: A-Z a-z 0-9 _ . -)");
      return false;
    }
  }
  if (v.size() > kMaxNameLength) {
    Err(a->line, w + " name " + Quote(v) + " is " + std::to_string(v.size()) +
                     " characters long (at most " + std::to_string(kMaxNameLength) + ")");
    return false;
  }
  if (v[0] == '.' || v[0] == '-') {
    Err(a->line, w + " name " + Quote(v) + " must not start with '.' or '-'");
    return false;
  }
  *out = v;
  return true;
}

bool Parser::NumberOk(const AttrValue& a, const char* attr, NumResult r, bool in_range,
                      const std::string& range) {
  if (r == NumResult::kSyntax) {
    Err(a.line, "invalid " + std::string(attr) + " " + Quote(a.value) + " (expected an integer " + range + ")");
    return false;
  }
  if (r == NumResult::kRange || !in_range) {
    Err(a.line, std::string(attr) + " " + a.value + " out of range (expected " + range + ")");
    return false;
  }
  return true;
}


bool Parser::Signed(const Element& e, const char* attr, int64_t lo, int64_t hi, int* out) {
  const AttrValue* a = e.Get(attr);
  if (a == nullptr) return false;
  int64_t v = 0;
  std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  NumResult r = ParseI64(a->value, &v, /*allow_hex=*/false);
  if (!NumberOk(*a, attr, r, v >= lo && v <= hi, range)) return false;
  *out = static_cast<int>(v);
  return true;
}

bool Parser::Bool(const Element& e, const char* attr, bool* out) {
  const AttrValue* a = e.Get(attr);
  if (a == nullptr) return false;
  if (!ParseBool(a->value, out)) {
    Err(a->line, "invalid " + std::string(attr) + " " + Quote(a->value) +
                     " (expected true, false, 1 or 0)");
    return false;
  }
  return true;
}

// XML forbids "--" inside a comment. RapidXML does not care, but xmllint, Python's
// ElementTree and editors reject such a file, and the same file must work for them too.
void CheckComments(const Node* parent, Diagnostics* diag) {
  for (const Node* c = parent->first_node(); c; c = c->next_sibling()) {
    if (c->type() == rapidxml::node_element) {
      CheckComments(c, diag);
      continue;
    }
    if (c->type() != rapidxml::node_comment) continue;
    std::string_view v(c->value(), c->value_size());
    size_t dd = v.find("--");
    if (dd == std::string_view::npos && !v.empty() && v.back() == '-') dd = v.size() - 1;
    if (dd != std::string_view::npos)
      diag->Error(diag->LineOf(c->value() + dd),
                  "'--' inside a comment (not allowed in XML; other XML tools reject the file)");
  }
}

void Parser::Run(const Node* doc, SystemConfig* cfg) {
  CheckComments(doc, &diag_);
  const Node* root = nullptr;
  for (const Node* c = doc->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_element) continue;
    if (root == nullptr) {
      root = c;
    } else {
      Err(diag_.LineOf(c->name()), "second root element <" + std::string(NameOf(c)) +
                                       "> (everything belongs inside <ccomm>)");
    }
  }
  if (root == nullptr) {
    Err(1, "no root element (expected <ccomm version=\"1\">)");
    return;
  }
  if (NameOf(root) != "ccomm") {
    Err(diag_.LineOf(root->name()), "root element is <" + std::string(NameOf(root)) +
                                        ">; expected <ccomm version=\"1\">");
    return;
  }
  Root(root, cfg);
  CrossCheck(cfg);
}

void Parser::Root(const Node* root, SystemConfig* cfg) {
  // xmlns:xsi / xsi:noNamespaceSchemaLocation let editors validate against signals.xsd.
  Element e(root, {"version", "xmlns:xsi", "xsi:noNamespaceSchemaLocation"}, &diag_);
  if (const AttrValue* v = e.Get("version")) {
    if (v->value != "1")
      Err(v->line, "unsupported format version " + Quote(v->value) +
                       " (this ccomm reads version 1)");
  } else if (!e.Has("version")) {
    Err(e.line(), "<ccomm> without version= (expected version=\"1\")");
  }
  CheckNoText(root, &diag_);

  int network_line = 0;
  int nodes_seen = 0, signals_seen = 0;
  int node_elements = 0;
  for (const Node* c = root->first_node("node"); c; c = c->next_sibling("node")) ++node_elements;
  std::vector<std::string> children = {"network", "node", "signal", "clock"};
  for (const ExtensionSection& s : kExtensionSections) children.push_back(s.name);
  for (const Node* c = root->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_element) continue;
    std::string_view name = NameOf(c);
    int line = diag_.LineOf(c->name());
    if (name == "network") {
      if (network_line) {
        Err(line, "second <network> (first at line " + std::to_string(network_line) + ")");
        continue;
      }
      network_line = line;
      Network(c, &cfg->network);
    } else if (name == "node") {
      if (++nodes_seen == static_cast<int>(kMaxNodes) + 1)
        Err(line, "too many nodes (at most " + std::to_string(kMaxNodes) + ")");
      NodeConfig node;
      NodeElement(c, node_elements == 1, &node);
      if (nodes_seen <= static_cast<int>(kMaxNodes)) cfg->nodes.push_back(std::move(node));
    } else if (name == "signal") {
      if (++signals_seen == static_cast<int>(kMaxSignals) + 1)
        Err(line, "too many signals (at most " + std::to_string(kMaxSignals) + ")");
      SignalConfig sig;
      SignalRefs refs;
      SignalElement(c, &sig, &refs);
      if (signals_seen <= static_cast<int>(kMaxSignals)) {
        cfg->signals.push_back(std::move(sig));
        refs_.push_back(std::move(refs));
      }
    } else if (IsExtensionSection(name)) {
      SectionElement section;
      ExtensionElement(c, &section);
      cfg->sections.push_back(std::move(section));
    } else if (name == "clock") {
      if (cfg->clock.present) {
        Err(line, "second <clock> (first at line " + std::to_string(cfg->clock.line) + ")");
        continue;
      }
      ClockElement(c, &cfg->clock);
    } else {
      std::string hint = Suggest(name, children);
      if (hint.empty()) {
        std::vector<std::string> all_but_last(children.begin(), children.end() - 1);
        hint = " (expected " + Join(all_but_last, ", ") + " or " + children.back() + ")";
      }
      Err(line, "unknown element <" + std::string(name) + "> in <ccomm>" + hint);
    }
  }
  if (nodes_seen == 0) Err(diag_.LineOf(root->name()), "no <node> defined");
}

void Parser::Network(const Node* n, NetworkConfig* net) {
  Element e(n, {"ethertype", "udp_port", "heartbeat_ms", "peer_timeout_ms", "summary_ms", "auth_key_file", "fanout",
                "multicast_base"},
            &diag_);
  CheckNoText(n, &diag_);
  if (n->first_node(nullptr))
    for (const Node* c = n->first_node(); c; c = c->next_sibling())
      if (c->type() == rapidxml::node_element)
        Err(diag_.LineOf(c->name()), "unknown element <" + std::string(NameOf(c)) +
                                         "> in <network> (it has no child elements)");
  // EtherType values below 0x0600 are 802.3 frame lengths, not protocol numbers.
  Unsigned(e, "ethertype", 0x0600, 0xFFFF, &net->ethertype, /*hex=*/true);
  Unsigned(e, "udp_port", 1, 65535, &net->udp_port);
  bool hb_ok = Unsigned(e, "heartbeat_ms", 1, kMaxHeartbeatMs, &net->heartbeat_ms) ||
               !e.Has("heartbeat_ms");
  bool pt_ok = Unsigned(e, "peer_timeout_ms", 1, kMaxPeerTimeoutMs, &net->peer_timeout_ms) ||
               !e.Has("peer_timeout_ms");
  if (hb_ok && pt_ok && net->peer_timeout_ms < 2 * net->heartbeat_ms) {
    const AttrValue* a = e.Get("peer_timeout_ms");
    Err(a ? a->line : e.line(),
        "peer_timeout_ms " + std::to_string(net->peer_timeout_ms) + " is less than twice " +
            "heartbeat_ms " + std::to_string(net->heartbeat_ms) +
            " (one lost heartbeat would declare the peer dead)");
  }
  if (e.Has("summary_ms") && Unsigned(e, "summary_ms", 0, kMaxSummaryMs, &net->summary_ms) &&
      net->summary_ms != 0 && net->summary_ms < kMinSummaryMs)
    Err(e.Get("summary_ms")->line, "summary_ms " + std::to_string(net->summary_ms) + " is below " +
                                       std::to_string(kMinSummaryMs) + " (0 turns summaries off)");
  if (const AttrValue* a = e.Get("fanout")) {
    if (a->value == "unicast")
      net->fanout = Fanout::kUnicast;
    else if (a->value == "multicast")
      net->fanout = Fanout::kMulticast;
    else
      Err(a->line, "unknown fanout " + Quote(a->value) + " (expected unicast or multicast)");
  }
  if (const AttrValue* a = e.Get("multicast_base")) {
    uint8_t q[4];
    if (!ParseIpv4(a->value, q))
      Err(a->line, "invalid multicast_base " + Quote(a->value) + " (expected an IPv4 address like 239.255.67.0)");
    else if (q[0] < 224 || q[0] > 239)
      Err(a->line, "multicast_base " + a->value + " is not in 224.0.0.0/4");
    else if (q[3] > 255 - kMaxNodes)  // the node groups, then the summary group (kSummaryGroup)
      Err(a->line, "multicast_base " + a->value + ": its last byte must leave room for " +
                       std::to_string(kMaxNodes) + " node groups and the summary group (at most " +
                       std::to_string(255 - kMaxNodes) + ")");
    else
      std::copy(q, q + 4, net->multicast_base);
  }
  if (const AttrValue* a = e.Get("auth_key_file")) {
    if (a->value.empty())
      Err(a->line, "empty auth_key_file (omit it to disable authentication)");
    else if (a->value[0] != '/')
      Err(a->line, "auth_key_file " + Quote(a->value) + " is not an absolute path");
    else
      net->auth_key_file = a->value;
  }
}

void Parser::NodeElement(const Node* n, bool only_node, NodeConfig* node) {
  Element e(n, {"name", "interface", "mac", "ip", "multicast", "transport", "monitor", "history"}, &diag_);
  node->line = e.line();
  Name(e, "node", &node->name);
  CheckNoText(n, &diag_);
  int realtime_line = 0;
  for (const Node* c = n->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml::node_element) continue;
    int line = diag_.LineOf(c->name());
    if (NameOf(c) != "realtime") {
      std::string hint = Suggest(NameOf(c), {"realtime"});
      if (hint.empty()) hint = " (expected realtime)";
      Err(line, "unknown element <" + std::string(NameOf(c)) + "> in <node>" + hint);
    } else if (realtime_line) {
      Err(line, "second <realtime> in node (first at line " + std::to_string(realtime_line) + ")");
    } else {
      realtime_line = line;
      Realtime(c, &node->realtime);
    }
  }

  if (e.Has("history") && Unsigned(e, "history", 2, 65536, &node->history) &&
      (node->history & (node->history - 1)))
    Err(e.Get("history")->line, "history " + std::to_string(node->history) +
                                    " is not a power of two (e.g. 256, 1024)");

  bool transport_ok = true;
  if (const AttrValue* a = e.Get("transport")) {
    if (a->value == "raw") {
      node->transport = TransportKind::kRaw;
    } else if (a->value == "udp") {
      node->transport = TransportKind::kUdp;
    } else {
      Err(a->line, "unknown transport " + Quote(a->value) + " (expected raw or udp)");
      transport_ok = false;
    }
  }
  if (const AttrValue* a = e.Get("interface")) {
    const std::string& v = a->value;
    bool ok = !v.empty() && v.size() <= kMaxInterfaceName && v != "." && v != "..";
    for (char c : v)
      if (c == '/' || c == ':' || static_cast<unsigned char>(c) <= ' ' || c == 0x7f) ok = false;
    if (!ok)
      Err(a->line, "invalid interface name " + Quote(v) +
                       " (1 to 15 characters, no '/', ':' or whitespace)");
    else
      node->interface = v;
  }
  if (const AttrValue* a = e.Get("mac")) {
    if (!ParseMac(a->value, node->mac)) {
      Err(a->line, "invalid mac " + Quote(a->value) + " (expected six hex pairs, e.g. 02:00:00:00:00:01)");
    } else if (node->mac[0] & 1) {
      Err(a->line, "mac " + a->value +
                       " is a multicast/broadcast address (omit mac= to send to broadcast)");
    } else if (std::all_of(node->mac, node->mac + 6, [](uint8_t b) { return b == 0; })) {
      Err(a->line, "mac 00:00:00:00:00:00 is not a valid station address");
    } else {
      node->has_mac = true;
    }
  }
  if (const AttrValue* a = e.Get("ip")) {
    uint8_t q[4];
    if (!ParseIpv4(a->value, q)) {
      Err(a->line, "invalid ip " + Quote(a->value) + " (expected an IPv4 address like 10.42.0.1)");
    } else if (q[0] >= 224 || (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0)) {
      Err(a->line, "ip " + a->value + " is not a unicast address");
    } else {
      node->ip = a->value;
    }
  }
  if (const AttrValue* a = e.Get("multicast")) {
    uint8_t q[4];
    if (!ParseIpv4(a->value, q)) {
      Err(a->line, "invalid multicast " + Quote(a->value) +
                       " (expected an IPv4 address like 239.42.0.1)");
    } else if (q[0] < 224 || q[0] > 239) {
      Err(a->line, "multicast " + a->value + " is not in 224.0.0.0/4");
    } else {
      node->multicast = a->value;
    }
  }
  if (const AttrValue* a = e.Get("monitor")) {
    // Comma-separated glob patterns on signal names (fnmatch: * ? [...]).
    std::string item;
    for (size_t i = 0; i <= a->value.size(); ++i) {
      const char c = i < a->value.size() ? a->value[i] : ',';
      if (c != ',') {
        if (c != ' ') item += c;
        continue;
      }
      if (item.empty())
        Err(a->line, "empty pattern in monitor " + Quote(a->value) + " (expected e.g. \"*\" or \"arm_*,cam_*\")");
      else
        node->monitor.push_back(item);
      item.clear();
    }
  }
  // A node that is alone in the file talks to nobody (shared memory only), so it needs
  // no network settings; Root() passes that in.
  if (transport_ok && !node->name.empty() && !only_node) {
    if (node->transport == TransportKind::kRaw && !e.Has("interface"))
      Err(e.line(), "raw node " + Quote(node->name) +
                        " needs interface= (the network interface its frames use)");
    if (node->transport == TransportKind::kUdp && !e.Has("ip"))
      Err(e.line(), "udp node " + Quote(node->name) +
                        " needs ip= (the IPv4 address its peers send to)");
  }
}

void Parser::Realtime(const Node* n, RealtimeConfig* rt) {
  Element e(n, {"mlockall", "priority", "cpu", "spin_us", "send_cycle_us", "send_phase_us", "send_lead_us", "launch_time"},
            &diag_);
  CheckNoText(n, &diag_);
  for (const Node* c = n->first_node(); c; c = c->next_sibling())
    if (c->type() == rapidxml::node_element)
      Err(diag_.LineOf(c->name()), "unknown element <" + std::string(NameOf(c)) +
                                       "> in <realtime> (it has no child elements)");
  Bool(e, "mlockall", &rt->mlockall);
  Signed(e, "priority", 1, 99, &rt->priority);
  Signed(e, "cpu", 0, kMaxCpu, &rt->cpu);
  Unsigned(e, "spin_us", 0, kMaxSpinUs, &rt->spin_us);
  SendCycle(e, rt);
}

// Send on the cycle (docs/config.md, <realtime>): the cycle divides one second (so boards
// whose TAI clocks differ by whole seconds share the grid), phase and lead below it.
void Parser::SendCycle(const Element& e, RealtimeConfig* rt) {
  const AttrValue* cycle = e.Get("send_cycle_us");
  if (!cycle) {
    for (const char* attr : {"send_phase_us", "send_lead_us", "launch_time"})
      if (const AttrValue* a = e.Get(attr)) Err(a->line, std::string(attr) + " without send_cycle_us");
    return;
  }
  rt->send_cycle_line = cycle->line;
  uint32_t c = 0;
  if (!Unsigned(e, "send_cycle_us", kMinSendCycleUs, kMaxSendCycleUs, &c)) return;
  if (kMaxSendCycleUs % c != 0) {
    Err(cycle->line, "send_cycle_us " + cycle->value + " does not divide one second (e.g. 250, 500, 1000, 2000)");
    return;
  }
  rt->send_cycle_us = c;
  // Phase and lead lie within the cycle: their range in the errors is the cycle's.
  if (!Unsigned(e, "send_phase_us", 0, c - 1, &rt->send_phase_us)) rt->send_phase_us = 0;
  rt->send_lead_us = std::min(kDefaultSendLeadUs, c / 2);
  if (const AttrValue* a = e.Get("send_lead_us")) {
    uint32_t lead = 0;
    if (Unsigned(e, "send_lead_us", 0, c - 1, &lead)) {
      if (lead < kMinSendLeadUs)
        Err(a->line, "send_lead_us " + a->value + " is too small (at least " + std::to_string(kMinSendLeadUs) +
                         " us: the send thread builds the frames in it)");
      else
        rt->send_lead_us = lead, rt->send_lead_line = a->line;
    }
  }
  if (const AttrValue* a = e.Get("launch_time")) {
    if (a->value == "auto")
      rt->launch_time = true;
    else if (a->value == "sleep")
      rt->launch_time = false;
    else
      Err(a->line, "unknown launch_time " + Quote(a->value) + " (expected auto or sleep)");
  }
}

}  // namespace config_detail
}  // namespace ccomm
