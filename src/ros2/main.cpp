// SPDX-License-Identifier: Apache-2.0
// ccomm-ros2: start-up (routes from the node's signals and the options), the two
// worker threads, signals and counters. See docs/integrations/ros2.md.
#include <ctime>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "bridge.h"
#include "section.h"
#include "common/public/platform_app.h"

namespace ccomm_ros2 {

ccomm_client* OpenWaiting(Bridge* b) {
  bool told = false;
  while (!b->stop.load()) {
    ccomm_client* c = nullptr;
    int rc = ccomm_open(b->node.empty() ? nullptr : b->node.c_str(), 0, &c);
    if (rc == 0) {
      if (told) fprintf(stderr, "ccomm-ros2: attached to node %s\n", ccomm_node_name(c));
      return c;
    }
    if (!told) {
      fprintf(stderr, "ccomm-ros2: cannot attach to node %s (%s): is ccommd running? waiting...\n",
              b->node.empty() ? "(default)" : b->node.c_str(), ccomm_strerror(rc));
      told = true;
    }
    ccomm::platform::SleepNsInterruptible(200 * 1000000u);
  }
  return nullptr;
}

bool ClaimNodeAndDomain(const Bridge* b) {
  // Beside the node's segment (its name with $CCOMM_SHM_PREFIX), so a test's own prefix
  // gets its own lock. The platform layer's exclusive lock: released by the kernel however
  // the holder ends, still held by a stopped (SIGSTOP) bridge, which would resume
  // publishing, and it names its holder. Group "ccomm" if it exists (as ccommd's node
  // lock): a bridge run by hand as root and then by the unit's user share the object.
  const std::string name = ccomm::platform::SegmentName(b->node) + ".ros2-domain" + std::to_string(b->opt.domain);
  int holder = 0;
  const int lock = ccomm::platform::LockExclusive(name.c_str(), ccomm::platform::NamedGroupId("ccomm"), &holder);
  if (lock == -EBUSY) {
    fprintf(stderr, "ccomm-ros2: another ccomm-ros2 (pid %s) already bridges node %s on DDS domain %d: "
                    "not starting a second one (every value would reach ROS 2 twice); stop it first "
                    "(lock /dev/shm%s)\n", holder > 0 ? std::to_string(holder).c_str() : "?", b->node.c_str(),
            b->opt.domain, name.c_str());
    return false;
  }
  if (lock < 0) {
    fprintf(stderr, "ccomm-ros2: cannot create the lock %s in /dev/shm: %s\n", name.c_str(), strerror(-lock));
    return false;
  }
  return true;  // held (never unlocked) until the process ends
}

bool ResolveRoutes(Bridge* b, ccomm_client* c, const std::vector<Route*>& routes) {
  (void)b;
  for (Route* r : routes) {
    ccomm_signal id = ccomm_find(c, r->name.c_str());
    ccomm_signal_desc d;
    if (id < 0 || ccomm_describe(c, id, &d) != 0) {
      fprintf(stderr, "ccomm-ros2: signal %s is gone from node %s: restart the bridge\n",
              r->name.c_str(), ccomm_node_name(c));
      return false;
    }
    if (r->id >= 0 && (d.type != r->desc.type || d.count != r->desc.count || d.is_event != r->desc.is_event)) {
      fprintf(stderr, "ccomm-ros2: signal %s changed its type in the new configuration: restart the bridge\n",
              r->name.c_str());
      return false;
    }
    r->id = id;
    r->desc = d;
    r->desc.name = r->desc.producer = nullptr;  // point into the segment: not kept
  }
  return true;
}

namespace {


bool AddRoute(Bridge* b, ccomm_client* c, const std::string& name, bool to_ros) {
  ccomm_signal id = ccomm_find(c, name.c_str());
  if (id < 0) {
    fprintf(stderr, "ccomm-ros2: no signal '%s' on node %s (see 'ccomm list')\n", name.c_str(), ccomm_node_name(c));
    return false;
  }
  ccomm_signal_desc d;
  ccomm_describe(c, id, &d);
  if (!to_ros && !d.produced_here) {
    fprintf(stderr, "ccomm-ros2: --subscribe %s: the signal is produced by node %s, not by %s; "
                    "only a producer's values can come from ROS 2\n", name.c_str(), d.producer, ccomm_node_name(c));
    return false;
  }
  if (!IsRosToken(name)) {
    fprintf(stderr, "ccomm-ros2: signal '%s' is not a valid ROS 2 topic name token (letters, digits, '_')\n",
            name.c_str());
    return false;
  }
  Route* r = new Route;
  r->name = name;
  r->topic = "rt/" + (b->opt.ros_namespace.empty() ? "" : b->opt.ros_namespace + "/") + name;
  r->to_ros = to_ros;
  r->desc = d;
  r->desc.name = r->desc.producer = nullptr;
  r->type = RosTypeFor(d.type, d.count);
  if (!r->type || !r->type->type_hash) {
    fprintf(stderr, "ccomm-ros2: signal %s: no ROS 2 type for ccomm type %d\n", name.c_str(), d.type);
    delete r;
    return false;
  }
  (to_ros ? b->to_ros : b->from_ros).push_back(r);
  return true;
}

bool BuildRoutes(Bridge* b, ccomm_client* c) {
  if (b->opt.publish_given) {
    for (const std::string& s : b->opt.publish)
      if (!AddRoute(b, c, s, true)) return false;
  } else {
    for (int i = 0; i < ccomm_signal_count(c); ++i) {
      ccomm_signal_desc d;
      if (ccomm_describe(c, i, &d) == 0 && d.consumed_here && !d.produced_here) {
        bool subscribed = false;
        for (const std::string& s : b->opt.subscribe) subscribed |= s == d.name;
        if (!subscribed && !AddRoute(b, c, d.name, true)) return false;
      }
    }
  }
  for (const std::string& s : b->opt.subscribe)
    if (!AddRoute(b, c, s, false)) return false;
  return true;
}

void PrintRoutes(const Bridge* b) {
  printf("%-4s %-28s %-32s %-8s %s\n", "dir", "DDS topic", "ROS 2 type", "kind", "QoS");
  for (const std::vector<Route*>* list : {&b->to_ros, &b->from_ros})
    for (const Route* r : *list) {
      char qos[96];
      if (r->desc.is_event)
        snprintf(qos, sizeof qos, "reliable, keep_all, volatile");
      else if (r->to_ros)
        snprintf(qos, sizeof qos, "reliable, keep_last 1, volatile, deadline %u ms", r->desc.stale_after_ms);
      else
        snprintf(qos, sizeof qos, "best_effort, keep_last 16, volatile");
      printf("%-4s %-28s %-32s %-8s %s  [%s x%u] %s\n", r->to_ros ? "->" : "<-", r->topic.c_str(),
             r->type->ros_name, r->desc.is_event ? "event" : "state", qos,
             ccomm_type_name(r->desc.type) ? ccomm_type_name(r->desc.type) : "?", r->desc.count,
             r->type->type_hash);
    }
}

}  // namespace

void PrintStats(const Bridge* b) {
  auto g = [](const std::atomic<uint64_t>& v) { return static_cast<unsigned long long>(v.load(std::memory_order_relaxed)); };
  printf("{\"node\":\"%s\",\"reopens\":%llu,\"signals\":{", b->node.c_str(), g(b->reopens));
  bool first = true;
  for (const std::vector<Route*>* list : {&b->to_ros, &b->from_ros})
    for (const Route* r : *list) {
      const RouteCounters& n = r->n;
      printf("%s\"%s\":{\"dir\":\"%s\",\"published\":%llu,\"skipped\":%llu,\"stale\":%llu,\"lost\":%llu,"
             "\"received\":%llu,\"written\":%llu,\"refused_length\":%llu,\"refused_value\":%llu,"
             "\"ccomm_errors\":%llu,\"dds_errors\":%llu,\"wrong_type_peers\":%llu,"
             "\"stamped_production\":%llu,\"stamped_local\":%llu}",
             first ? "" : ",", r->name.c_str(), r->to_ros ? "to_ros" : "from_ros", g(n.published),
             g(n.skipped), g(n.stale), g(n.lost), g(n.received), g(n.written), g(n.refused_length),
             g(n.refused_value), g(n.ccomm_errors), g(n.dds_errors), g(n.wrong_type_peers),
             g(n.stamped_production), g(n.stamped_local));
      first = false;
    }
  printf("}}\n");
  fflush(stdout);
}

}  // namespace ccomm_ros2

int main(int argc, char** argv) {
  using namespace ccomm_ros2;
  Bridge b;
  int rc = ParseOptions(argc, argv, &b.opt);
  if (rc >= 0) return rc;
  if (b.opt.check_only) {
    if (b.opt.config_path.empty()) {
      fprintf(stderr, "ccomm-ros2: --check needs --config FILE (no /etc/ccomm/signals.xml)\n");
      return 2;
    }
    return CheckConfig(b.opt.config_path);
  }
  b.node = b.opt.node;

  // Waits for ccommd (a default SIGINT still ends the program here: nothing to undo yet).
  ccomm_client* c = OpenWaiting(&b);
  if (!c) return 1;
  b.node = ccomm_node_name(c);
  if (!ApplyConfigSection(&b.opt, b.node)) {
    ccomm_close(c);
    return 2;
  }
  bool ok = BuildRoutes(&b, c);
  ccomm_close(c);
  if (!ok) return 2;
  if (b.to_ros.empty() && b.from_ros.empty()) {
    fprintf(stderr, "ccomm-ros2: nothing to bridge: node %s consumes no signal and no --subscribe "
                    "was given\n", b.node.c_str());
    return 2;
  }
  if (b.opt.list_only) {
    PrintRoutes(&b);
    return 0;
  }
  if (!ClaimNodeAndDomain(&b)) return 2;
  if (!CreateDdsEntities(&b)) {
    DestroyDdsEntities(&b);
    return 1;
  }
  fprintf(stderr, "ccomm-ros2: node %s, DDS domain %d, %zu topic(s) to ROS 2, %zu from ROS 2\n",
          b.node.c_str(), b.opt.domain, b.to_ros.size(), b.from_ros.size());
  if (b.opt.verbose) PrintRoutes(&b);

  // Signals go to the main thread only (sigtimedwait below); the workers inherit the mask.
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);

  std::thread to_ros(RunToRos, &b);
  std::thread from_ros(RunFromRos, &b);
  timespec tick{0, 100 * 1000000L};
  double since_stats = 0;
  while (!b.stop.load()) {
    int sig = sigtimedwait(&set, nullptr, &tick);
    if (sig == SIGINT || sig == SIGTERM) b.stop = true;
    else if (sig == SIGUSR1) PrintStats(&b);
    since_stats += 0.1;  // approximate: the interval is for watching, not for measuring
    if (b.opt.stats_interval_s > 0 && since_stats >= b.opt.stats_interval_s) {
      PrintStats(&b);
      since_stats = 0;
    }
  }
  to_ros.join();
  from_ros.join();
  PrintStats(&b);
  DestroyDdsEntities(&b);
  return b.fatal.load();
}
