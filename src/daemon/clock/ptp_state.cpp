// SPDX-License-Identifier: Apache-2.0
// ptp4l's management protocol (IEEE 1588-2008 clause 15, linuxptp's TIME_STATUS_NP
// extension) and the clock state derived from its answers. The socket to ptp4l is
// platform code: clock/posix/ptp_socket.cpp (its Unix datagram socket), ptp_socket_windows.cpp.
#include "daemon/clock/ptp_state.h"

#include <errno.h>
#include <string.h>

#include "common/platform.h"

namespace ccomm {
namespace ptp {

namespace {

constexpr size_t kHeaderSize = 34;           // PTP common header
constexpr size_t kManagementSize = 48;       // header + target port (10) + hops (2) + action (2)
static_assert(kManagementSize == kHeaderSize + 10 + 2 + 2, "management message layout");
constexpr size_t kTlvHeaderSize = 6;         // type, length, management id
constexpr uint8_t kMessageManagement = 0x0D;
constexpr uint8_t kActionGet = 0, kActionResponse = 2;
constexpr uint16_t kTlvManagement = 0x0001;

uint16_t Get16(const uint8_t* p) { return static_cast<uint16_t>(p[0] << 8 | p[1]); }
uint32_t Get32(const uint8_t* p) { return uint32_t{Get16(p)} << 16 | Get16(p + 2); }
int64_t Get64(const uint8_t* p) { return static_cast<int64_t>(uint64_t{Get32(p)} << 32 | Get32(p + 4)); }
void Put16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v >> 8);
  p[1] = static_cast<uint8_t>(v);
}

}  // namespace

const char* ClockStateName(ClockState s) {
  switch (s) {
    case ClockState::kNone: return "none";
    case ClockState::kSyncing: return "syncing";
    case ClockState::kSynced: return "synced";
    case ClockState::kLost: return "lost";
  }
  return "?";
}

size_t BuildGet(uint8_t* out, size_t cap, uint16_t id, uint16_t sequence, uint8_t domain) {
  const size_t len = kManagementSize + kTlvHeaderSize;
  if (cap < len) return 0;
  memset(out, 0, len);
  out[0] = kMessageManagement;  // transportSpecific 0
  out[1] = 2;                   // versionPTP
  Put16(out + 2, static_cast<uint16_t>(len));
  out[4] = domain;
  // sourcePortIdentity (20..29): zero; ptp4l answers to the socket address.
  Put16(out + 30, sequence);
  out[32] = 0x04;               // controlField: management
  out[33] = 0x7F;               // logMessageInterval
  memset(out + 34, 0xFF, 10);   // targetPortIdentity: all clocks, all ports
  out[44] = 0;                  // startingBoundaryHops 0: the local ptp4l only (pmc -b 0)
  out[45] = 0;                  // boundaryHops
  out[46] = kActionGet;
  Put16(out + 48, kTlvManagement);
  Put16(out + 50, 2);           // lengthField: the id, no data
  Put16(out + 52, id);
  return len;
}

bool ParseReply(const uint8_t* buf, size_t len, Reply* out) {
  if (len < kManagementSize + kTlvHeaderSize) return false;
  if ((buf[0] & 0x0F) != kMessageManagement || (buf[1] & 0x0F) != 2) return false;
  const size_t msg_len = Get16(buf + 2);
  if (msg_len > len || msg_len < kManagementSize + kTlvHeaderSize) return false;
  if ((buf[46] & 0x0F) != kActionResponse) return false;
  const uint8_t* tlv = buf + kManagementSize;
  if (Get16(tlv) != kTlvManagement) return false;  // e.g. MANAGEMENT_ERROR_STATUS
  const size_t tlv_len = Get16(tlv + 2);            // from the id on
  if (tlv_len < 2 || kManagementSize + 4 + tlv_len > msg_len) return false;
  const uint8_t* data = tlv + kTlvHeaderSize;
  const size_t data_len = tlv_len - 2;
  Reply r;
  r.id = Get16(tlv + 4);
  if (r.id == kIdTimeStatusNp) {
    // master_offset (8), ingress_time (8), cumulativeScaledRateOffset (4),
    // scaledLastGmPhaseChange (4), gmTimeBaseIndicator (2), lastGmPhaseChange (12),
    // gmPresent (4), gmIdentity (8): 50 bytes.
    if (data_len < 50) return false;
    r.master_offset_ns = Get64(data);
    r.gm_present = Get32(data + 38) != 0;
  } else if (r.id == kIdPortDataSet) {
    // portIdentity (10), portState (1), logMinDelayReqInterval (1),
    // peerMeanPathDelay (8, ns << 16), ...: 26 bytes.
    if (data_len < 26) return false;
    r.port_state = data[10];
    r.mean_path_delay_ns = Get64(data + 12) / 65536;
  } else {
    return false;
  }
  *out = r;
  return true;
}

void Monitor::Answer(const Reply& r, uint64_t now_ns) {
  last_answer_ns_ = now_ns ? now_ns : 1;
  if (r.id == kIdTimeStatusNp) {
    have_status_ = true;
    offset_ns_ = r.master_offset_ns;
    gm_present_ = r.gm_present;
  } else if (r.id == kIdPortDataSet) {
    have_port_ = true;
    port_state_ = r.port_state;
    path_delay_ns_ = r.mean_path_delay_ns;
  }
}

bool Monitor::Evaluate(uint64_t now_ns) {
  ClockState s;
  if (!last_answer_ns_) {
    s = ClockState::kNone;
  } else if (now_ns - last_answer_ns_ > kLostAfterNs) {
    s = ClockState::kLost;
  } else if (!have_port_ || !have_status_) {
    s = ClockState::kSyncing;
  } else if (port_state_ == kPortFaulty || port_state_ == kPortDisabled) {
    s = ClockState::kLost;
  } else if (port_state_ == kPortSlave) {
    const int64_t off = offset_ns_ < 0 ? -offset_ns_ : offset_ns_;
    s = off <= synced_within_ns_ ? ClockState::kSynced : ClockState::kSyncing;
  } else if (port_state_ == kPortMaster && !gm_present_) {
    s = ClockState::kSynced;  // this clock is the grandmaster: the reference itself
  } else {
    s = ClockState::kSyncing;
  }
  const bool changed = s != state_;
  state_ = s;
  return changed;
}

uint64_t Monitor::NextDueNs() const {
  if (path_.empty()) return UINT64_MAX;
  if (awaited_) return 0;
  const uint64_t lost = last_answer_ns_ ? last_answer_ns_ + kLostAfterNs + 1 : UINT64_MAX;
  return next_poll_ns_ < lost ? next_poll_ns_ : lost;
}

bool Monitor::Tick(uint64_t now_ns) {
  Drain(now_ns);
  if (now_ns >= next_poll_ns_) {
    next_poll_ns_ = now_ns + kPollNs;
    Poll(now_ns);
  }
  return Evaluate(now_ns);
}

}  // namespace ptp
}  // namespace ccomm
