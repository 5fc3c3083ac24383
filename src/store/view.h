// SPDX-License-Identifier: Apache-2.0
// The system view: what ccommd learned from every node's summary frames (wire/summary.h),
// in a small shared-memory object of its own ("/ccomm.<node>.view", next to the node's
// segment, not part of its layout). ccommd creates it at start and is its only writer;
// clients (libccomm's ccomm_view_*) map it read-only.
//
// Layout: ViewHeader, then ViewNode[node_count], then ViewRow[node_count][signal_count].
// Invariants:
//  - every field after the header's `state` becomes kViewReady is a 64-bit atomic word
//    (so concurrent reads are race-free);
//  - node n's record and its rows are written by one thread at a time (the receive thread
//    for other nodes, the supervision thread for the node itself), inside the seqlock
//    `ViewNode::seq` (odd while a write is under way): a reader that saw the same even
//    seq before and after copying has a consistent copy of that node;
//  - the header's dimensions never change while the object exists.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

namespace ccomm {
namespace store {

constexpr uint32_t kViewMagic = 0x43435657;  // "CCVW"
constexpr uint32_t kViewVersion = 2;  // 2: node clock words
enum ViewState : uint32_t { kViewInitializing = 0, kViewReady = 1 };

struct ViewHeader {
  uint32_t magic, version, node_count, signal_count, self, summary_ms;
  uint64_t size;  // bytes of the whole object
  std::atomic<uint32_t> state;
  uint32_t reserved;
  // Summary traffic of this node's ccommd (counters only grow).
  std::atomic<uint64_t> summaries_tx;       // summary frames sent
  std::atomic<uint64_t> summaries_rx;       // accepted and applied
  std::atomic<uint64_t> summaries_refused;  // from unknown/wrong sources, wrong config, not for us
  std::atomic<uint64_t> summaries_old;      // not newer than the sender's last applied one
  std::atomic<uint64_t> summaries_send_errors;
};

/// Words of a node record.
enum ViewNodeWord : uint32_t {
  kVwLastRxNs = 0,   // our CLOCK_MONOTONIC at its last summary (0 = none yet)
  kVwTimeoutNs,      // it counts as alive while its last summary is younger than this
  kVwUptimeNs,       // its ccommd's uptime, as of that summary
  kVwPeersAlive,     // bit i: it hears node i
  kVwFramesRx, kVwFramesTx, kVwFramesBad, kVwFramesLost, kVwSocketDrops,
  kVwCycleMs,        // its time to send all parts of its summary
  kVwSummaries,      // summary parts applied
  kVwClockState,     // its ptp::ClockState (wire::SummaryHead::clock_state)
  kVwClockErrorNs,   // bound on its clock's offset from the grandmaster, wire::kSummaryNoClockError: none
  kVwClockOffsetNs,  // int64: its CLOCK_REALTIME - CLOCK_MONOTONIC, as of that summary
  kVwNodeWords
};

struct ViewNode {
  std::atomic<uint32_t> seq;
  uint32_t reserved;
  std::atomic<uint64_t> w[kVwNodeWords];
};

/// One signal as a node reports it.
struct ViewRowCopy {
  bool present = false;  // the node reported this signal
  uint8_t role = 0, flags = 0;  // wire::SummaryRole, wire::SummaryRecordFlags
  uint32_t rate_mhz = 0;
  uint64_t lost = 0;
  uint32_t age_ms = 0;   // as reported (wire::kSummaryNoAge: never)
  uint64_t rx_ns = 0;    // our clock when the report arrived (the age has grown since)
};

struct ViewRow {
  std::atomic<uint64_t> w[4];  // [0] present | role << 8 | flags << 16 | rate_mhz << 32,
                               // [1] lost, [2] age_ms, [3] rx_ns
};

struct ViewNodeCopy {
  uint64_t w[kVwNodeWords] = {};
};

class View {
 public:
  View() = default;
  View(const View&) = delete;
  View& operator=(const View&) = delete;
  ~View() { Close(); }

  /// ccommd: replaces any object of that name with a fresh one (mode 0660, group `gid`
  /// if >= 0). 0 or -errno, with a message in `error`.
  int Create(const std::string& name, uint32_t nodes, uint32_t signals, uint32_t self, uint32_t summary_ms,
             int gid, std::string* error);
  /// Clients: maps an existing object read-only. 0 or -errno (-EPROTO: not a view of this
  /// version, or not initialised yet).
  int OpenReadOnly(const std::string& name);
  void Close();
  /// ccommd at a clean stop: removes the name Create gave the object (readers that mapped
  /// it keep their mapping). Nothing if this object did not create one.
  void Remove();
  bool is_open() const { return base_ != nullptr; }

  const ViewHeader* header() const { return static_cast<const ViewHeader*>(base_); }
  ViewHeader* mutable_header() { return static_cast<ViewHeader*>(base_); }

  // Writer (ccommd): Begin, Set*, End per node.
  void BeginWrite(uint32_t node);
  void SetNodeWord(uint32_t node, ViewNodeWord w, uint64_t v);
  void SetRow(uint32_t node, uint32_t signal, uint8_t role, uint8_t flags, uint32_t rate_mhz, uint64_t lost,
              uint32_t age_ms, uint64_t rx_ns);
  void EndWrite(uint32_t node);

  // Readers: false if the node was being written for too long (retry later).
  bool ReadNode(uint32_t node, ViewNodeCopy* out) const;
  bool ReadRow(uint32_t node, uint32_t signal, ViewRowCopy* out) const;

  /// The object's name for node `node` ("/ccomm.<node>.view", CCOMM_SHM_PREFIX applies).
  static std::string NameFor(const std::string& node);
  /// Bytes an object of these dimensions takes.
  static size_t SizeFor(uint32_t nodes, uint32_t signals);

 private:
  ViewNode* Node(uint32_t n) const;
  ViewRow* Row(uint32_t n, uint32_t s) const;
  void* base_ = nullptr;
  size_t size_ = 0;
  std::string created_name_;  // set by Create: the name Remove() removes
};

}  // namespace store
}  // namespace ccomm
