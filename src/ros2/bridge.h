// SPDX-License-Identifier: Apache-2.0
// ccomm-ros2: the bridge between a node's ccomm signals and ROS 2 (Cyclone DDS).
// One route per bridged signal; the ccomm -> ROS 2 routes belong to one thread and the
// ROS 2 -> ccomm routes to another, each with its own ccomm handle.
#pragma once

#include <ccomm/ccomm.h>
#include <dds/dds.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace ccomm_ros2 {

// kWrite: a sample's production time on the common time base when known, else its arrival.
enum class StampMode { kWrite, kArrival };

struct Options {
  std::string node;                  // empty: $CCOMM_NODE, else the hostname
  std::string ros_namespace = "ccomm";
  bool namespace_given = false;      // on the command line (wins over <ros2>)
  int domain = 0;
  bool domain_given = false;         // --domain (wins over <ros2>, which wins over $ROS_DOMAIN_ID)
  std::string config_path;           // signals.xml with the <ros2> section ("" = none)
  bool config_given = false;
  std::vector<std::string> publish;  // ccomm -> ROS 2; empty: every signal consumed here
  bool publish_given = false;
  std::vector<std::string> subscribe;  // ROS 2 -> ccomm: signals produced here
  StampMode stamp = StampMode::kWrite;
  int priority = 0;                  // SCHED_FIFO priority of the ccomm -> ROS 2 thread (0: none)
  double stats_interval_s = 0;       // 0: stats only on SIGUSR1 and at exit
  bool list_only = false;
  bool check_only = false;           // --check: validate the configuration's <ros2> sections, exit
  int verbose = 0;
};

// Parses argv into `o`; returns -1 to go on, else the exit status (help printed: 0,
// usage error: 2, with a message on stderr).
int ParseOptions(int argc, char** argv, Options* o);

// Takes what the command line left open from the <ros2 node=NODE> section of
// o->config_path (config_section.cpp). False with the file's errors on stderr.
bool ApplyConfigSection(Options* o, const std::string& node);

// The ROS 2 message type of a ccomm signal (see dds_types.cpp).
struct RosType {
  const char* ros_name;                // "std_msgs/msg/Float64"
  const dds_topic_descriptor_t* desc;  // DDS type std_msgs::msg::dds_::Float64_
  const char* type_hash;               // "RIHS01_<64 hex>"
  bool is_array;                       // *MultiArray
};
// nullptr if no std_msgs type carries this ccomm type.
const RosType* RosTypeFor(int32_t ccomm_type, uint32_t count);

// Counters of one route, written by its thread, read by the stats printer (relaxed).
struct RouteCounters {
  std::atomic<uint64_t> published{0};       // samples written to DDS
  std::atomic<uint64_t> skipped{0};         // state values overwritten before the bridge read them
                                            // (with a history tap: the bridge fell N behind)
  std::atomic<uint64_t> stale{0};           // fresh -> stale transitions (ROS sees a deadline miss)
  std::atomic<uint64_t> lost{0};            // events ccomm reported lost before the bridge, and
                                            // states that never reached this node (history tap)
  std::atomic<uint64_t> dds_errors{0};      // dds_write/take failures
  std::atomic<uint64_t> received{0};        // DDS samples taken
  std::atomic<uint64_t> written{0};         // of those, written into ccomm
  std::atomic<uint64_t> refused_length{0};  // array length (or layout) is not the signal's count
  std::atomic<uint64_t> refused_value{0};   // a value the signal's type cannot hold (bool 0/1)
  std::atomic<uint64_t> ccomm_errors{0};    // ccomm_write failed (e.g. event queue full)
  std::atomic<uint64_t> wrong_type_peers{0};  // DDS writers on this topic with another type
  std::atomic<uint64_t> stamped_production{0};  // samples stamped with their production time
  std::atomic<uint64_t> stamped_local{0};       // ... with their arrival: production time unknown
};

struct Route {
  std::string name;   // ccomm signal name
  std::string topic;  // "rt/<namespace>/<name>"
  ccomm_signal id = -1;
  ccomm_signal_desc desc{};  // name/producer pointers are not kept valid across reopens
  const RosType* type = nullptr;
  bool to_ros = true;
  dds_entity_t topic_entity = 0, endpoint = 0;  // writer (to_ros) or reader
  void* sample = nullptr;   // preallocated DDS sample (dds_alloc, freed at exit)
  uint64_t last_seq = 0;    // to_ros: seq of the last value published
  uint64_t last_lost = 0;   // to_ros: the handle's lost count already counted
  bool fresh = false;       // to_ros: the last read was fresh
  bool history = false;     // to_ros: a received state read through the node's history tap
  ccomm_history_cursor cursor{};  // ... its cursor (every value, in order)
  uint64_t last_overrun = 0;      // ... the cursor's overrun already counted
  int stamp_code = -2;            // to_ros: ccomm_production_age_code of the last stamp (-1: no view)
  RouteCounters n;
};

struct Bridge {
  Options opt;
  std::string node;  // the ccomm node actually opened
  dds_entity_t participant = 0;
  std::vector<Route*> to_ros, from_ros;
  std::atomic<uint64_t> reopens{0};
  std::atomic<bool> stop{false};
  std::atomic<int> fatal{0};  // non-zero: exit status a worker asks for
  ccomm_view* to_ros_view = nullptr;  // the ccomm -> ROS 2 thread's system view (production ages)
  uint32_t view_generation = 0;       // ccommd generation it was opened under
  int64_t view_recheck_ns = 0;        // when to open it once more after a ccommd restart (0: no)

  Bridge() = default;
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;
  ~Bridge() {  // every exit path of main (usage errors, --list) frees the routes
    for (Route* r : to_ros) delete r;
    for (Route* r : from_ros) delete r;
  }
};

// Opens the node's segment, waiting (with one message) while ccommd has not created it.
// Returns nullptr only when asked to stop.
ccomm_client* OpenWaiting(Bridge* b);
// One bridge per node and DDS domain: takes a lock the process holds until it ends.
// False (with a message naming the holder) when another bridge holds it.
bool ClaimNodeAndDomain(const Bridge* b);
// A writer offering the route's current deadline (stale_after_ms): the deadline is an
// immutable QoS in Cyclone DDS, so the writer is replaced when it changed. False with a
// message if the new writer cannot be created.
bool OfferCurrentDeadline(Bridge* b, Route* r, uint32_t offered_ms);
// Finds the routes' signals again after a (re)open and checks that their type did not
// change; false (with a message) if a route cannot be served by this handle.
bool ResolveRoutes(Bridge* b, ccomm_client* c, const std::vector<Route*>& routes);

// DDS entities of every route; false with a message on stderr.
bool CreateDdsEntities(Bridge* b);
void DestroyDdsEntities(Bridge* b);

// Worker threads (return when b->stop is set or a fatal error happened).
void RunToRos(Bridge* b);
void RunFromRos(Bridge* b);

// One JSON line with every counter, to stdout.
void PrintStats(const Bridge* b);

}  // namespace ccomm_ros2
