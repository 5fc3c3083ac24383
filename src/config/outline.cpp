// SPDX-License-Identifier: Apache-2.0
// The configuration as the owner of an extension section reads it (outline.h).
#include "config/public/outline.h"

#include <utility>

#include "config/config.h"
#include "config/text.h"

namespace ccomm {

const SectionAttribute* SectionElement::Find(std::string_view attr) const {
  for (const SectionAttribute& a : attributes)
    if (a.name == attr) return &a;
  return nullptr;
}

bool ConfigOutline::HasNode(std::string_view name) const {
  for (const std::string& n : nodes)
    if (n == name) return true;
  return false;
}

const OutlineSignal* ConfigOutline::FindSignal(std::string_view name) const {
  for (const OutlineSignal& s : signals)
    if (s.name == name) return &s;
  return nullptr;
}

std::string ConfigError(const std::string& path, int line, const std::string& message) {
  if (line <= 0) return path + ": error: " + message;
  return path + ":" + std::to_string(line) + ": error: " + message;
}

std::string ConfigQuote(std::string_view word) { return config_detail::Quote(word); }

bool SplitConfigList(std::string_view value, std::vector<std::string>* items) {
  std::vector<std::string_view> views;
  items->clear();
  if (!config_detail::SplitList(value, &views)) return false;
  for (std::string_view v : views) items->emplace_back(v);
  return true;
}

namespace {

void Outline(SystemConfig&& cfg, ConfigOutline* out) {
  ConfigOutline o;
  o.path = cfg.path;
  for (const NodeConfig& n : cfg.nodes) o.nodes.push_back(n.name);
  for (const SignalConfig& s : cfg.signals) {
    OutlineSignal sig;
    sig.name = s.name;
    sig.producer = cfg.nodes[s.producer].name;
    for (uint32_t c : s.consumers) sig.consumers.push_back(cfg.nodes[c].name);
    sig.line = s.line;
    o.signals.push_back(std::move(sig));
  }
  o.sections = std::move(cfg.sections);
  *out = std::move(o);
}

}  // namespace

bool LoadConfigOutline(const std::string& path, ConfigOutline* out, std::string* error) {
  SystemConfig cfg;
  if (!LoadConfig(path, &cfg, error)) return false;
  Outline(std::move(cfg), out);
  return true;
}

bool ParseConfigOutline(const std::string& text, const std::string& path, ConfigOutline* out,
                        std::string* error) {
  SystemConfig cfg;
  if (!ParseConfig(text, path, &cfg, error)) return false;
  Outline(std::move(cfg), out);
  return true;
}

}  // namespace ccomm
