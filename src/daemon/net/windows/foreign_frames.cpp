// SPDX-License-Identifier: Apache-2.0
// The watch for frames of the other transport (foreign_frames.h) where it cannot run
// (Windows): it needs a packet socket, so it stays off and counts nothing.
#include <errno.h>

#include "daemon/net/foreign_frames.h"

namespace ccomm {

int ForeignFrameWatch::Open(const NetworkConfig& /*net*/, const NodeConfig& /*self*/, TransportKind /*kind*/) {
  return -ENOSYS;  // "Function not implemented" in the log (the C runtime has no text for ENOTSUP)
}
uint32_t ForeignFrameWatch::Poll(uint64_t /*now_ns*/) { return 0; }
void ForeignFrameWatch::Close() { fd_ = -1; }

}  // namespace ccomm
