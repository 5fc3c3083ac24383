// SPDX-License-Identifier: Apache-2.0
// The resolved configuration as JSON (`ccommd --check FILE --json`): what tools that
// need signals.xml (the 20-sim 4C generator, scripts) read instead of parsing the XML
// themselves, so the file has one parser.
#pragma once

#include <string>

#include "config/config.h"

namespace ccomm {

/// One JSON object: {"format": 1, "path", "hash", "network": {...}, "nodes": [...],
/// "signals": [...], "sections": [...]}; every cross reference resolved (producer and
/// consumers by node name), every default applied; extension sections (<ros2>) as
/// element trees (name, line, attributes, children). docs/config.md, "As JSON".
std::string ConfigToJson(const SystemConfig& cfg);

}  // namespace ccomm
