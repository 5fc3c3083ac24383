// SPDX-License-Identifier: Apache-2.0
// What libccomm's other units (history.cpp, client_info.cpp) need of a handle, without the handle's
// definition (client_handle.h, for the units that build and use it).
#pragma once

#include "ccomm/ccomm.h"
#include "store/segment.h"

namespace ccomm {
namespace client {

/// The segment `c` maps (c must not be null).
const store::Segment& SegmentOf(const ccomm_client* c);

}  // namespace client
}  // namespace ccomm
