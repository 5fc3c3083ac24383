// SPDX-License-Identifier: Apache-2.0
// ptp4l's configuration for one node from <clock> of signals.xml (ccommd --clock-config,
// run by the ccomm-ptp4l unit before ptp4l starts): one file, the same on every board,
// gives every board its PTP role.
#pragma once

#include <cstdint>
#include <string>

#include "config/config.h"

namespace ccomm {

// The ptp4l.conf text for `node`; empty and *error set if the file has no <clock>.
std::string Ptp4lConfig(const SystemConfig& cfg, uint32_t node, std::string* error);

}  // namespace ccomm
