// SPDX-License-Identifier: Apache-2.0
// Raw Ethernet where it is not built (Windows): what transport_raw.cpp and
// foreign_frames.cpp provide on Linux. A node whose config uses transport="raw" is
// refused with a message that says what to do (ccommd --check says it too, main.cpp);
// the watch for frames of the other transport stays off (it needs a packet socket).
#include <errno.h>

#include "daemon/foreign_frames.h"
#include "daemon/transport.h"

namespace ccomm {

const bool kRawEthernetBuilt = false;

int OpenRawTransport(const NetworkConfig& /*net*/, const NodeConfig& self, int /*recv_timeout_ms*/,
                     Transport* /*out*/, std::string* error) {
  *error = RawEthernetUnavailable(self);
  return -ENOTSUP;
}

int ForeignFrameWatch::Open(const NetworkConfig& /*net*/, const NodeConfig& /*self*/, TransportKind /*kind*/) {
  return -ENOSYS;  // "Function not implemented" in the log (the C runtime has no text for ENOTSUP)
}
uint32_t ForeignFrameWatch::Poll(uint64_t /*now_ns*/) { return 0; }
void ForeignFrameWatch::Close() { fd_ = -1; }

}  // namespace ccomm
