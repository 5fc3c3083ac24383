// SPDX-License-Identifier: Apache-2.0
// The configuration's public interface for programs that own a section of signals.xml
// (the ROS 2 bridge owns <ros2>): what such a program reads instead of config/config.h.
//
// The core parser (src/config/) knows the names of the extension sections it accepts in
// <ccomm> (kExtensionSections) but not their meaning: it checks their structure only
// (attributes well-formed and not repeated, no text, the same for every child element)
// and keeps each as an element tree with line numbers. The owner checks the rest and
// reports with ConfigError(), so every message about the file reads FILE:LINE: error: ...
//
// Standard headers only: applications include this one, never the parser's internals
// (tests/structure/check_layering.py checks both).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace ccomm {

/// Extension sections the core accepts as children of <ccomm>, and the program that
/// reads and checks each (`ccommd --check --json` names it with the section).
struct ExtensionSection {
  const char* name;
  const char* owner;
};
constexpr ExtensionSection kExtensionSections[] = {
    {"ros2", "ccomm-ros2"},  // docs/integrations/ros2.md
};

struct SectionAttribute {
  std::string name;
  std::string value;  // entity references decoded
  int line = 0;
};

/// One element of an extension section: its attributes and child elements in file order.
struct SectionElement {
  std::string name;
  int line = 0;
  std::vector<SectionAttribute> attributes;  // names unique (the core refuses repeats)
  std::vector<SectionElement> children;

  /// The attribute called `attr`, or nullptr.
  const SectionAttribute* Find(std::string_view attr) const;
};

/// A signal as the owner of a section sees it: names, not ids.
struct OutlineSignal {
  std::string name;
  std::string producer;                // node name
  std::vector<std::string> consumers;  // node names (monitor= expanded)
  int line = 0;
};

/// A valid configuration as the owner of a section sees it.
struct ConfigOutline {
  std::string path;                     // the file, for messages
  std::vector<std::string> nodes;       // node names in file order (= node ids)
  std::vector<OutlineSignal> signals;   // in file order (= signal ids)
  std::vector<SectionElement> sections; // extension sections, in file order

  /// Whether a node of that name exists.
  bool HasNode(std::string_view name) const;
  /// The signal of that name, or nullptr.
  const OutlineSignal* FindSignal(std::string_view name) const;
};

/// Loads `path` with the same parser and checks as `ccommd --check`; false with every
/// error ("FILE:LINE: error: MESSAGE" lines) in `error` when the file is not valid.
bool LoadConfigOutline(const std::string& path, ConfigOutline* out, std::string* error);
/// Same, from text in memory; `path` is used only in messages.
bool ParseConfigOutline(const std::string& text, const std::string& path, ConfigOutline* out,
                        std::string* error);
/// "PATH:LINE: error: MESSAGE" (no line number when line <= 0), as every configuration error.
std::string ConfigError(const std::string& path, int line, const std::string& message);
/// 'word' with control characters escaped, as configuration errors quote words.
std::string ConfigQuote(std::string_view word);
/// A list attribute's items (consumers=, publish=): separated by blanks and/or single
/// commas; false on an empty item (",," or a comma at either end).
bool SplitConfigList(std::string_view value, std::vector<std::string>* items);

}  // namespace ccomm
