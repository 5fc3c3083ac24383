// SPDX-License-Identifier: Apache-2.0
// System configuration: the parsed form of /etc/ccomm/signals.xml.
//
// One file describes the whole system (every node, every signal), so the same file is
// flashed to every board. Signal ids are the signals' positions in the file and node ids
// the nodes' positions; both are identical on every board that loads the same file,
// which the wire format checks through `hash`.
//
// Parsing happens once at start-up (it allocates freely); nothing here is used on a
// real-time path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/value_type.h"
#include "config/public/outline.h"

namespace ccomm {

/// Parses a type name; false if unknown.
bool ParseValueType(const std::string& name, ValueType* out);

enum class SignalKind : uint8_t { kState = 0, kEvent = 1 };
enum class TransportKind : uint8_t { kRaw = 0, kUdp = 1 };
/// How a producing node reaches its consumers: one frame per consumer (unicast), or one
/// frame per cycle to the node's own multicast group that its consumers join.
enum class Fanout : uint8_t { kUnicast = 0, kMulticast = 1 };

constexpr uint32_t kMaxSignals = 4096;
constexpr uint32_t kMaxNodes = 64;
constexpr uint32_t kMaxArrayCount = 65535;  // the wire's 16-bit entry count
constexpr uint32_t kMaxNameLength = 63;
/// Largest value (count * element size) one signal may carry (64 KiB). Values that do not
/// fit one frame travel in fragments (docs/protocol.md, "Large values").
constexpr uint32_t kMaxValueBytes = 65536;
/// Largest event queue of one signal (queue_depth x value bytes): 64 MiB, what 65536
/// values of 1 KiB took before values could be larger; a segment is built in memory.
constexpr uint64_t kMaxQueueBytes = uint64_t{64} << 20;

struct RealtimeConfig {
  bool mlockall = true;
  int priority = 0;   // SCHED_FIFO priority for ccommd's I/O threads; 0 = SCHED_OTHER
  int cpu = -1;       // CPU affinity for ccommd's I/O threads; -1 = any
  uint32_t spin_us = 0;  // busy-poll window after activity before sleeping (0 = pure event-driven)
  // Send on the cycle (daemon/engine/send_cycle.h): periodic frames leave at k * period +
  // send_phase_us of a clock the boards share. 0 = off. Local policy (not in the hash).
  uint32_t send_cycle_us = 0;    // divides one second
  uint32_t send_phase_us = 0;    // < send_cycle_us
  uint32_t send_lead_us = 0;     // wake this early (< send_cycle_us); 0 in the file = default
  bool launch_time = true;       // launch_time="auto": SO_TXTIME where the kernel can; "sleep": never
  int send_cycle_line = 0;       // line of the send_cycle_us attribute, for messages
  int send_lead_line = 0;        // line of the send_lead_us attribute (0: the default)
};

struct NodeConfig {
  std::string name;
  std::string interface;       // network interface, e.g. "eth0"
  bool has_mac = false;
  uint8_t mac[6] = {};         // unicast destination for raw frames; broadcast if !has_mac
  std::string ip;              // IPv4 unicast address for UDP (dotted quad), may be empty
  std::string multicast;       // optional IPv4 multicast group for UDP (unicast fan-out)
  std::vector<std::string> monitor;  // monitor="*" or "a*,b*": consumes every matching signal
                                     // produced elsewhere (expanded into the consumer lists)
  TransportKind transport = TransportKind::kRaw;
  RealtimeConfig realtime;
  uint32_t history = 0;        // history="N": received states keep their last N values (power of
                               // two; 0 = none). Local policy, not in the config hash.
  int line = 0;                // line of <node> in the file, for messages
};

// stale_by="...": a consumer's age (and so fresh/stale) of a state counts from the value's
// arrival on that board (default), or from its write on the producer when both boards'
// clocks are synced (docs/design.md, "Time"; arrival again while they are not).
enum class StaleBy : uint8_t { kArrival, kProduction };

struct SignalConfig {
  std::string name;
  ValueType type = ValueType::kDouble;
  uint32_t count = 1;          // array length; 1 = scalar
  SignalKind kind = SignalKind::kState;
  uint32_t producer = 0;       // node id
  std::vector<uint32_t> consumers;  // node ids
  uint32_t stale_after_ms = 0;  // 0 = never goes stale
  StaleBy stale_by = StaleBy::kArrival;  // what a consumer's age counts from (local policy)
  bool has_safe_value = false;
  std::vector<uint8_t> safe_value;  // count * element size bytes, host byte order
  uint32_t period_us = 0;      // 0 = event-driven (sent on every write); >0 = sent every period,
                               // batched with every other due signal for the same destination.
                               // XML: period_ms="1" or "0.1", or rate_hz="1000" (one of them)
  uint32_t queue_depth = 64;   // event signals: ring capacity (power of two)
  int line = 0;

  size_t value_bytes() const { return count * ValueTypeSize(type); }
};

struct NetworkConfig {
  uint16_t ethertype = 0x88B5;
  uint16_t udp_port = 47800;
  uint32_t heartbeat_ms = 100;
  uint32_t peer_timeout_ms = 300;
  uint32_t summary_ms = 1000;  // node summaries (the system view): one full round per this
                               // many ms, at most one frame per 100 ms; 0 = none (local policy)
  std::string auth_key_file;   // empty = no authentication
  Fanout fanout = Fanout::kUnicast;
  uint8_t multicast_base[4] = {239, 255, 67, 0};  // UDP group of node n: base + n
};

// <clock>: linuxptp between the boards (local policy, not in the hash: a wrong domain shows
// as a clock that never syncs, not as refused frames). Parsed by clock_section.cpp;
// ccommd --clock-config writes ptp4l's configuration from it (daemon/clock/ptp_config.cpp).
struct ClockConfig {
  bool present = false;
  uint32_t domain = 0;                    // PTP domainNumber, 0..127
  std::vector<std::string> grandmasters;  // nodes that may be grandmaster, best first; the rest are slave-only
  bool hardware = false;                  // timestamping="hardware" (the NIC's clock + phc2sys), else software
  int sync_interval_log = -3;             // logSyncInterval: Sync every 2^n s (-7..4)
  std::string socket = "/var/run/ptp4l";  // ptp4l's management socket (uds_address), ccommd asks it
  int line = 0;
};

struct SystemConfig {
  std::string path;            // file it was read from
  NetworkConfig network;
  std::vector<NodeConfig> nodes;
  std::vector<SignalConfig> signals;
  std::vector<SectionElement> sections;  // extension sections such as <ros2>, checked for
                                        // structure only: their owners read them (outline.h)
  ClockConfig clock;             // <clock>, at most one
  uint32_t hash = 0;           // FNV-1a over a canonical form of what both ends must agree on
                               // (node names/order, signal name/type/count/kind/producer/
                               // consumers, ethertype, udp port); not whitespace or comments,
                               // not local policy (stale_after, safe values, realtime). Frames carry it.

  /// Node id by name, or -1.
  int FindNode(const std::string& name) const;
  /// Signal id by name, or -1.
  int FindSignal(const std::string& name) const;
};

/// Loads and validates `path`. On failure returns false and fills `error` with one or
/// more lines "FILE:LINE: error: MESSAGE". On success every cross reference (producer,
/// consumers) is resolved and every limit above holds.
bool LoadConfig(const std::string& path, SystemConfig* out, std::string* error);
/// Same, from text in memory; `path` is used only in messages.
bool ParseConfig(const std::string& text, const std::string& path, SystemConfig* out,
                 std::string* error);

}  // namespace ccomm
