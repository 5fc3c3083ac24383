// SPDX-License-Identifier: Apache-2.0
// When a value is stale: the one rule ccomm_read, ccomm_get_signal_stats, ccommd's
// supervision (stale transitions) and its node summaries apply.
#pragma once

#include <stdint.h>

namespace ccomm::store {

/// A signal with `stale_after_ns` (0: never stale) is stale when nothing was received yet
/// or its value is older than that: `age_ns` since it reached this node.
constexpr bool IsStale(bool received, uint64_t age_ns, uint64_t stale_after_ns) {
  return stale_after_ns != 0 && (!received || age_ns > stale_after_ns);
}

}  // namespace ccomm::store
