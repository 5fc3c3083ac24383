// SPDX-License-Identifier: Apache-2.0
// The in-memory layout shared by every std_msgs *MultiArray_ sample idlc generates
// (checked by static_asserts in dds_types.cpp), so one code path fills and checks all.
#pragma once

#include <cstdint>

#include "std_msgs.h"

namespace ccomm_ros2 {

struct ArraySample {
  std_msgs_msg_dds__MultiArrayLayout_ layout_;
  struct {
    uint32_t maximum;
    uint32_t length;
    void* buffer;
    bool release;
  } data_;
};

}  // namespace ccomm_ros2
