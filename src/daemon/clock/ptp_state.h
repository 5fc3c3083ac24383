// SPDX-License-Identifier: Apache-2.0
// This board's clock synchronisation as linuxptp's ptp4l sees it, read over ptp4l's
// management socket (a Unix datagram socket, /var/run/ptp4l by default: what
// `pmc -u -b 0 'GET TIME_STATUS_NP'` and `'GET PORT_DATA_SET'` ask). ccommd's supervision
// thread calls Tick() on its ticks (every 10 ms while answers are due, NextDueNs); it sends a query once a second and takes answers
// without ever blocking, so a slow or dead ptp4l costs nothing on any real-time path.
//
// States (docs/design.md, "Time"):
//   none     no ptp4l has answered since ccommd started (no socket, nobody listening)
//   syncing  ptp4l answers, its port is not yet a synchronised slave (listening,
//            uncalibrated, ...) or its offset from the master is above the threshold
//   synced   port SLAVE with |offset from master| <= threshold, or MASTER of a domain
//            in which this clock is the grandmaster (the reference itself)
//   lost     ptp4l answered before and no longer does (killed, hung), or its port is
//            FAULTY or DISABLED
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

namespace ccomm {
namespace ptp {

enum class ClockState : uint32_t { kNone = 0, kSyncing = 1, kSynced = 2, kLost = 3 };
const char* ClockStateName(ClockState s);

// A bound on this clock's offset from the grandmaster, in ns, or -1 when there is none
// (not synced): 0 for the grandmaster itself; for a synced slave ptp4l's own estimate,
// |offset from master| plus its mean path delay (a path's asymmetry shifts the offset by at
// most half the round trip; with E2E the delay is not asked for and counts as 0).
inline int64_t ClockErrorNs(ClockState state, uint8_t port_state, int64_t offset_ns, int64_t path_delay_ns);

// IEEE 1588 port states (portState of PORT_DATA_SET).
enum PortState : uint8_t {
  kPortUnknown = 0, kPortInitializing = 1, kPortFaulty = 2, kPortDisabled = 3, kPortListening = 4,
  kPortPreMaster = 5, kPortMaster = 6, kPortPassive = 7, kPortUncalibrated = 8, kPortSlave = 9,
};

inline int64_t ClockErrorNs(ClockState state, uint8_t port_state, int64_t offset_ns, int64_t path_delay_ns) {
  if (state != ClockState::kSynced) return -1;
  if (port_state != kPortSlave) return 0;  // synced and not a slave: the grandmaster
  const uint64_t off = offset_ns < 0 ? 0 - static_cast<uint64_t>(offset_ns) : static_cast<uint64_t>(offset_ns);
  const uint64_t delay = path_delay_ns < 0 ? 0 : static_cast<uint64_t>(path_delay_ns);
  const uint64_t sum = off + delay;
  return sum > uint64_t{INT64_MAX} ? INT64_MAX : static_cast<int64_t>(sum);
}

// Management ids asked for.
constexpr uint16_t kIdPortDataSet = 0x2004;
constexpr uint16_t kIdTimeStatusNp = 0xC000;

// A GET management message for `id`, to the local clock only (boundaryHops 0, every
// port), in PTP domain `domain` (ptp4l ignores management messages of another domain,
// also on its Unix socket: pmc -d): 54 bytes written to `out`. Returns its length, 0 if
// `cap` is too small.
size_t BuildGet(uint8_t* out, size_t cap, uint16_t id, uint16_t sequence, uint8_t domain = 0);

// What an answer carried (fields of the id it answered).
struct Reply {
  uint16_t id = 0;
  // TIME_STATUS_NP
  int64_t master_offset_ns = 0;
  bool gm_present = false;
  // PORT_DATA_SET
  uint8_t port_state = kPortUnknown;
  int64_t mean_path_delay_ns = 0;  // peerMeanPathDelay (P2P); E2E: CURRENT_DATA_SET has it, not asked
};
// Parses a RESPONSE management message of one of the ids above. False for anything else
// (wrong type, version, action, truncated, another id, an error status TLV): ignored.
bool ParseReply(const uint8_t* buf, size_t len, Reply* out);

// The state machine of the module comment, fed by Tick() (socket) or, in tests, by
// Answer()/Silence() directly.
class Monitor {
 public:
  static constexpr uint64_t kPollNs = 1'000'000'000;
  // Two polls unanswered: ptp4l is gone (or hung).
  static constexpr uint64_t kLostAfterNs = 2 * kPollNs + kPollNs / 2;

  Monitor() = default;
  ~Monitor();
  // Where ptp4l listens (empty: never asked, the state stays none) and the largest
  // |offset from master| of a slave that counts as synced.
  void Configure(std::string uds_path, int64_t synced_within_ns, uint8_t domain) {
    path_ = std::move(uds_path);
    synced_within_ns_ = synced_within_ns;
    domain_ = domain;
  }
  Monitor(const Monitor&) = delete;
  Monitor& operator=(const Monitor&) = delete;

  // Supervision thread, every tick: never blocks. True when the state changed.
  bool Tick(uint64_t now_ns);
  // When Tick next has something to do (the supervision's schedule): at once (0) while
  // answers to the last poll are due, else the next poll or the instant the last answer
  // grows too old (kLostAfterNs); UINT64_MAX if never asked.
  uint64_t NextDueNs() const;
  // The pieces of Tick, for tests: an answer arrived / time passed.
  void Answer(const Reply& r, uint64_t now_ns);
  bool Evaluate(uint64_t now_ns);

  ClockState state() const { return state_; }
  uint8_t port_state() const { return port_state_; }
  int64_t offset_ns() const { return offset_ns_; }
  int64_t path_delay_ns() const { return path_delay_ns_; }
  const std::string& path() const { return path_; }

 private:
  bool OpenSocket();
  void Poll(uint64_t now_ns);
  void Drain(uint64_t now_ns);

  std::string path_;
  int64_t synced_within_ns_ = 1000000;
  uint8_t domain_ = 0;
  int fd_ = -1;
  uint16_t sequence_ = 0;
  // Answers still to come for the last poll: the socket is read only while one is (no
  // ptp4l, the usual case off a PTP network: sendto fails and the idle tick makes no
  // system call for it).
  uint8_t awaited_ = 0;
  uint64_t next_poll_ns_ = 0;
  uint64_t last_answer_ns_ = 0;  // 0: never
  bool have_status_ = false, have_port_ = false;
  ClockState state_ = ClockState::kNone;
  uint8_t port_state_ = kPortUnknown;
  int64_t offset_ns_ = 0;
  int64_t path_delay_ns_ = 0;
  bool gm_present_ = false;
};

}  // namespace ptp
}  // namespace ccomm
