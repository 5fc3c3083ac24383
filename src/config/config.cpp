// SPDX-License-Identifier: Apache-2.0
// Parser and validator for signals.xml (format: docs/config.md, schema: docs/signals.xsd).
//
// RapidXML builds the DOM; everything else (line numbers, entity decoding, every semantic
// check) is done here so that every mistake in the file is reported with FILE:LINE, and
// all of them at once rather than one per run.
//
// The parser is split by job: xml_input (RapidXML, depth guard), text (numbers, lists,
// addresses, entities), diagnostics (messages), parser/parser_signal (elements),
// cross_check (checks across elements); this file ties them together and hashes.

#include "config/config.h"


#include <algorithm>
#include <cerrno>
#include <cstring>

#include "common/platform.h"
#include "config/parser.h"

namespace ccomm {

bool ParseValueType(const std::string& name, ValueType* out) {
  for (ValueType t : kAllValueTypes) {
    if (name == ValueTypeName(t)) {
      *out = t;
      return true;
    }
  }
  return false;
}

int SystemConfig::FindNode(const std::string& name) const {
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].name == name) return static_cast<int>(i);
  return -1;
}

int SystemConfig::FindSignal(const std::string& name) const {
  for (size_t i = 0; i < signals.size(); ++i)
    if (signals[i].name == name) return static_cast<int>(i);
  return -1;
}

using namespace config_detail;

namespace {

// A real configuration is well under 1 MiB (4096 signals is about 600 KiB); refuse
// anything absurd rather than allocating for it.
constexpr size_t kMaxFileBytes = 16u << 20;

// Canonical form hashed into SystemConfig::hash (specified in docs/config.md, "Config
// hash"); other implementations must produce the same bytes.
std::string CanonicalForm(const SystemConfig& cfg) {
  std::string s = "ccomm-config 1\n";
  s += "network " + std::to_string(cfg.network.ethertype) + " " +
       std::to_string(cfg.network.udp_port) + "\n";
  // Only when not the default, so files without fanout= keep their hash.
  if (cfg.network.fanout == Fanout::kMulticast) {
    const uint8_t* b = cfg.network.multicast_base;
    s += "fanout multicast " + std::to_string(b[0]) + "." + std::to_string(b[1]) + "." +
         std::to_string(b[2]) + "." + std::to_string(b[3]) + "\n";
  }
  for (const NodeConfig& n : cfg.nodes) s += "node " + n.name + "\n";
  for (const SignalConfig& sig : cfg.signals) {
    std::vector<uint32_t> consumers = sig.consumers;
    std::sort(consumers.begin(), consumers.end());  // the set matters, not the order
    std::string list;
    for (uint32_t c : consumers) {
      if (!list.empty()) list += ',';
      list += cfg.nodes[c].name;
    }
    s += "signal " + sig.name + " " + ValueTypeName(sig.type) + " " + std::to_string(sig.count) +
         " " + (sig.kind == SignalKind::kEvent ? "event" : "state") + " " +
         cfg.nodes[sig.producer].name + " " + (list.empty() ? "-" : list) + "\n";
  }
  return s;
}

uint32_t Fnv1a32(const std::string& s) {
  uint32_t h = 2166136261u;
  for (char c : s) {
    h ^= static_cast<uint8_t>(c);
    h *= 16777619u;
  }
  return h;
}


}  // namespace

bool ParseConfig(const std::string& text, const std::string& path, SystemConfig* out,
                 std::string* error) {
  // RapidXML needs a NUL-terminated buffer; parse_non_destructive leaves it unchanged,
  // so names and values point into it and their line numbers can be computed.
  std::vector<char> buf(text.begin(), text.end());
  buf.push_back('\0');
  Parser parser(path, buf.data(), text.size());
  Diagnostics& diag = parser.diag();

  if (text.size() > kMaxFileBytes) {
    diag.Error(0, "file is " + std::to_string(text.size()) + " bytes; at most " +
                      std::to_string(kMaxFileBytes) + " accepted");
  } else if (size_t nul = text.find('\0'); nul != std::string::npos) {
    diag.Error(diag.LineOf(buf.data() + nul), "NUL byte in file (not a text file?)");
  } else if (size_t deep = FindTooDeep(text); deep != std::string::npos) {
    diag.Error(diag.LineOf(buf.data() + deep), "elements nested more than " +
                                                   std::to_string(kMaxXmlDepth) + " levels deep");
  } else {
    rapidxml::xml_document<char> doc;
    XmlFailure failure;
    if (!RunXmlParse(&doc, buf.data(), &failure)) {
      std::string what = failure.what;
      // RapidXML reports a truncated file by what it expected next; say what happened.
      if (failure.where == buf.data() + text.size() && what != "unexpected end of data")
        what = "unexpected end of data (" + what + ")";
      diag.Error(diag.LineOf(failure.where), "XML syntax error: " + what);
    } else {
      SystemConfig cfg;
      cfg.path = path;
      parser.Run(&doc, &cfg);
      if (diag.empty()) {
        cfg.hash = Fnv1a32(CanonicalForm(cfg));
        *out = std::move(cfg);
        if (error) error->clear();
        return true;
      }
    }
  }
  if (error) *error = diag.Render();
  return false;
}

bool LoadConfig(const std::string& path, SystemConfig* out, std::string* error) {
  auto fail = [&](const std::string& what) {
    if (error) *error = path + ": error: " + what;
    return false;
  };
  std::string text;
  uint64_t size = 0;
  const int r = platform::ReadRegularFile(path.c_str(), kMaxFileBytes, &text, &size);
  if (r == -EINVAL) return fail("not a regular file");
  if (r == -EFBIG)
    return fail("file is " + std::to_string(size) + " bytes; at most " + std::to_string(kMaxFileBytes) + " accepted");
  if (r == -EIO) return fail(std::string("read failed: ") + std::strerror(errno));
  if (r != 0) return fail(std::string("cannot open: ") + std::strerror(-r));
  return ParseConfig(text, path, out, error);
}

}  // namespace ccomm
