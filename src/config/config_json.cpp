// SPDX-License-Identifier: Apache-2.0
#include "config/config_json.h"

#include <stdio.h>

#include <vector>

namespace ccomm {
namespace {

void Str(std::string* o, const std::string& s) {
  *o += '"';
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      *o += '\\';
      *o += static_cast<char>(c);
    } else if (c < 0x20) {
      char b[8];
      snprintf(b, sizeof b, "\\u%04x", c);
      *o += b;
    } else {
      *o += static_cast<char>(c);
    }
  }
  *o += '"';
}

void Key(std::string* o, const char* k) {
  Str(o, k);
  *o += ':';
}

void Num(std::string* o, const char* k, unsigned long long v) {
  Key(o, k);
  *o += std::to_string(v);
  *o += ',';
}

void Text(std::string* o, const char* k, const std::string& v) {
  Key(o, k);
  Str(o, v);
  *o += ',';
}

void Names(std::string* o, const char* k, const std::vector<std::string>& v) {
  Key(o, k);
  *o += '[';
  for (size_t i = 0; i < v.size(); ++i) {
    if (i) *o += ',';
    Str(o, v[i]);
  }
  *o += "],";
}

void Bool(std::string* o, const char* k, bool v) {
  Key(o, k);
  *o += v ? "true," : "false,";
}

void Close(std::string* o, char bracket) {
  if (!o->empty() && o->back() == ',') o->pop_back();
  *o += bracket;
}

// "k":{...}, with the members `members()` writes.
template <class Members>
void Object(std::string* o, const char* k, Members&& members) {
  Key(o, k);
  *o += '{';
  members();
  Close(o, '}');
  *o += ',';
}

// "k":[{...},...] of n objects, with the members `members(i)` writes for object i.
template <class Members>
void Objects(std::string* o, const char* k, size_t n, Members&& members) {
  Key(o, k);
  *o += '[';
  for (size_t i = 0; i < n; ++i) {
    *o += '{';
    members(i);
    Close(o, '}');
    *o += ',';
  }
  Close(o, ']');
  *o += ',';
}

// The members of one extension element: name, line, attributes (name: value), children.
void Section(std::string* o, const SectionElement& e) {
  Text(o, "name", e.name);

  Num(o, "line", static_cast<unsigned long long>(e.line));
  Object(o, "attributes", [&] {
    for (const SectionAttribute& a : e.attributes) Text(o, a.name.c_str(), a.value);
  });
  Objects(o, "children", e.children.size(), [&](size_t i) { Section(o, e.children[i]); });
}

}  // namespace

std::string ConfigToJson(const SystemConfig& cfg) {
  std::string o = "{";
  Num(&o, "format", 1);
  Text(&o, "path", cfg.path);
  char hash[16];
  snprintf(hash, sizeof hash, "%08x", cfg.hash);
  Text(&o, "hash", hash);  // as ccommd --check and the frames' config hash field show it
  Object(&o, "network", [&] {
    Num(&o, "ethertype", cfg.network.ethertype);
    Num(&o, "udp_port", cfg.network.udp_port);
    Num(&o, "heartbeat_ms", cfg.network.heartbeat_ms);
    Num(&o, "peer_timeout_ms", cfg.network.peer_timeout_ms);
    Num(&o, "summary_ms", cfg.network.summary_ms);
    Text(&o, "fanout", cfg.network.fanout == Fanout::kMulticast ? "multicast" : "unicast");
    Bool(&o, "authenticated", !cfg.network.auth_key_file.empty());
  });
  Objects(&o, "nodes", cfg.nodes.size(), [&](size_t n) {
    const NodeConfig& node = cfg.nodes[n];
    Num(&o, "id", n);
    Text(&o, "name", node.name);
    Text(&o, "transport", node.transport == TransportKind::kUdp ? "udp" : "raw");
    Text(&o, "interface", node.interface);
    Text(&o, "ip", node.ip);
    Num(&o, "history", node.history);
    Num(&o, "line", static_cast<unsigned long long>(node.line));
  });
  Objects(&o, "signals", cfg.signals.size(), [&](size_t s) {
    const SignalConfig& sig = cfg.signals[s];
    Num(&o, "id", s);
    Text(&o, "name", sig.name);
    Text(&o, "type", ValueTypeName(sig.type));
    Num(&o, "count", sig.count);
    Num(&o, "value_bytes", sig.value_bytes());
    Text(&o, "kind", sig.kind == SignalKind::kEvent ? "event" : "state");
    Text(&o, "producer", cfg.nodes[sig.producer].name);
    std::vector<std::string> consumers;
    for (uint32_t c : sig.consumers) consumers.push_back(cfg.nodes[c].name);
    Names(&o, "consumers", consumers);
    Num(&o, "stale_after_ms", sig.stale_after_ms);
    Text(&o, "stale_by", sig.stale_by == StaleBy::kProduction ? "production" : "arrival");
    Num(&o, "period_us", sig.period_us);
    Num(&o, "queue_depth", sig.queue_depth);
    Bool(&o, "has_safe_value", sig.has_safe_value);
    Num(&o, "line", static_cast<unsigned long long>(sig.line));
  });
  // Extension sections as the core keeps them (outline.h): their owners give them meaning.
  Objects(&o, "sections", cfg.sections.size(), [&](size_t i) {
    for (const ExtensionSection& s : kExtensionSections)
      if (cfg.sections[i].name == s.name) Text(&o, "owner", s.owner);  // who checks its content
    Section(&o, cfg.sections[i]);
  });
  Close(&o, '}');
  o += '\n';
  return o;
}

}  // namespace ccomm
