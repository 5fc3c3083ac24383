// SPDX-License-Identifier: Apache-2.0
// ccommd's side of the system view (every node as it reports itself; the one name of the
// concept, docs/design.md): every node's ccommd sends a node summary, its part of the
// view (wire/summary.h), to the other nodes, rate-limited, from the supervision tick
// (never the real-time loops), and writes the summaries it receives into the view object
// (store/view.h). The reading side is libccomm's ccomm_view_* (client/system_view_reader.cpp),
// which `ccomm stats --all` prints.
//
// Threads: Tick() runs on the main thread and writes only this node's record; Receive()
// runs on the receive thread and writes only other nodes' records (the view's seqlock is
// per node, with one writer each). Everything is allocated in Start().
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "config/config.h"
#include "daemon/net/transport.h"
#include "daemon/security/auth.h"
#include "store/segment.h"
#include "store/view.h"
#include "wire/summary.h"

namespace ccomm {

class SystemViewWriter {
 public:
  /// What Receive() did with a summary frame; the daemon counts the refusals in its
  /// usual counters (same meaning as for data frames).
  /// kOwn: this node's own summary, looped back by the summary group (UDP multicast
  /// loops back so nodes sharing a host hear each other): ignored, not counted.
  enum class Verdict { kApplied, kOld, kOwn, kUnknownSender, kWrongSource, kNotForUs, kWrongHash, kUnknownSignal };

  /// Creates the view object; `transport`/`auth` may be unusable (local-only node: the
  /// view then holds this node only). 0 or -errno with `error`.
  int Start(const SystemConfig& cfg, uint32_t self, TransportKind kind, bool force_udp, store::Segment* segment,
            Transport* transport, const auth::FrameAuth* auth, int gid, std::string* error);
  /// Clean stop: the view's name goes with the daemon (`ccomm stats --all` then says no
  /// ccommd is running; a tool that mapped it keeps its copy). A killed ccommd leaves it,
  /// and its next start replaces it.
  void Stop() { view_.Remove(); }
  /// Supervision tick: sends the next summary part when it is due, refreshes this node's
  /// record. Returns the number of frames sent (tests count them).
  uint32_t Tick(uint64_t now);
  /// A frame DecodeHeader accepted with kFlagSummary, after authentication.
  Verdict Receive(const uint8_t* frame, const wire::FrameHeader& h, uint64_t now, const PeerAddress& from);

  /// Receive thread (it writes other nodes' records): true, with `node`'s CLOCK_REALTIME -
  /// CLOCK_MONOTONIC, if its newest summary is current (within its timeout at `now`) and
  /// says its clock is synced.
  bool SyncedClockOffset(uint32_t node, uint64_t now, int64_t* offset_ns) const;

  /// Time between two parts and the number of parts (0 if summaries are off).
  uint64_t interval_ns() const { return interval_ns_; }
  uint32_t parts() const { return parts_; }
  /// For the supervision's schedule (Supervisor::NextTickNs): when Tick next sends a part
  /// or refreshes this node's record.
  uint64_t next_due_ns() const { return next_ns_; }

 private:
  struct Dest {
    PeerAddress addr;
    uint16_t dest = 0;  // node id, or wire::kDestAll for a shared (broadcast/group) address
    uint32_t seq = 0;
  };
  struct Reported {  // one signal of this node's summary
    uint32_t id = 0;
    uint8_t role = 0;
    uint64_t last_count = 0;     // writes (produced) / rx (consumed) at the last cycle start
    uint64_t last_write_ns = 0;  // produced: its newest value's write time (NewestWriteNs), 0 = never
    wire::SummaryRecord rec;     // as of the current cycle's start
  };
  struct SenderState {
    uint64_t last_send_ns = 0;   // newest send_time_ns applied
    uint64_t last_rx_ns = 0;
    uint32_t ipv4 = 0;           // UDP: its configured address (network order), 0 = any
  };

  void Snapshot(uint64_t now);
  uint64_t NewestWriteNs(uint32_t id);
  void SendPart(uint32_t part, uint64_t now);
  void SetHeadWords(uint32_t node, const wire::SummaryHead& head);  // the head's words; inside Begin/EndWrite
  void WriteSelf(const wire::SummaryHead& head, uint32_t first, uint32_t end, uint64_t now);

  const SystemConfig* cfg_ = nullptr;
  uint32_t self_ = 0;
  store::Segment* segment_ = nullptr;
  Transport* transport_ = nullptr;
  const auth::FrameAuth* auth_ = nullptr;
  store::View view_;
  std::vector<Dest> dests_;
  std::vector<Reported> reported_;
  std::vector<SenderState> senders_;
  uint64_t start_ns_ = 0, interval_ns_ = 0, next_ns_ = 0, cycle_start_ns_ = 0;
  std::vector<uint64_t> scratch_;  // the largest produced value (NewestWriteNs)
  uint32_t parts_ = 0, next_part_ = 0;
  wire::SummaryHead head_;  // node-level part of the current cycle
  alignas(8) uint8_t buf_[wire::kMaxFrameSize];
};

}  // namespace ccomm
