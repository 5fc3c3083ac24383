// SPDX-License-Identifier: Apache-2.0
// segment_host CONFIG NODE SECONDS: creates NODE's shared-memory segment from CONFIG as
// ccommd would (the daemon's segment builder), says "ready", keeps it SECONDS or until
// its standard input closes, then exits. tests/windows/run uses it under Wine so that
// programs built against the packaged ccomm.dll can attach to a segment of another
// process (ccommd.exe itself is not ported yet: docs/install.md "Windows").
#include <stdio.h>
#include <stdlib.h>

#include <string>

#include "common/platform.h"
#include "config/config.h"
#include "daemon/engine/segment_builder.h"
#include "store/segment.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: segment_host CONFIG NODE SECONDS\n");
    return 2;
  }
  ccomm::SystemConfig cfg;
  std::string error;
  if (!ccomm::LoadConfig(argv[1], &cfg, &error)) {
    fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  int node = -1;
  for (size_t i = 0; i < cfg.nodes.size(); ++i)
    if (cfg.nodes[i].name == argv[2]) node = static_cast<int>(i);
  if (node < 0) {
    fprintf(stderr, "segment_host: no node '%s' in %s\n", argv[2], argv[1]);
    return 1;
  }
  ccomm::store::Segment segment;
  bool adopted = false;
  const std::string name = ccomm::store::SegmentName(argv[2]);
  if (ccomm::CreateOrAdoptSegment(&segment, cfg, static_cast<uint32_t>(node), name, -1, &adopted, &error) != 0) {
    fprintf(stderr, "segment_host: %s\n", error.c_str());
    return 3;
  }
  // Clients check that a daemon is alive: this process stands in for it.
  segment.header()->daemon_pid.store(static_cast<int32_t>(ccomm::platform::ProcessId()));
  printf("ready %s\n", name.c_str());
  fflush(stdout);
  const uint64_t end = ccomm::platform::MonotonicNs() + static_cast<uint64_t>(atoi(argv[3])) * 1000000000ull;
  while (ccomm::platform::MonotonicNs() < end) {
    segment.header()->daemon_heartbeat_ns.store(ccomm::platform::MonotonicNs());
    ccomm::platform::SleepNs(10000000);
  }
  return 0;
}
