// SPDX-License-Identifier: Apache-2.0
// ccomm-ros2 command line.
#include <getopt.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "bridge.h"
#include "section.h"

namespace ccomm_ros2 {
namespace {

const char kUsage[] =
    "Usage: ccomm-ros2 [OPTIONS]     (also: ccomm [--node NODE] ros2 [OPTIONS])\n"
    "\n"
    "Bridges this node's ccomm signals to ROS 2 over Eclipse Cyclone DDS: every signal\n"
    "this node consumes appears as the ROS 2 topic /NAMESPACE/SIGNAL (DDS topic\n"
    "rt/NAMESPACE/SIGNAL, std_msgs types), and signals this node produces can be fed from\n"
    "ROS 2 topics. A stale signal is not re-published: ROS 2 subscribers see the DDS\n"
    "deadline (= stale_after_ms) missed. See docs/integrations/ros2.md.\n"
    "\n"
    "Options:\n"
    "  -n, --node NODE           ccomm node to attach to (default: $CCOMM_NODE, else the\n"
    "                            hostname); ccommd must run as that node\n"
    "  -c, --config FILE         signals.xml whose <ros2 node=NODE> element gives the\n"
    "                            namespace, domain, publish and subscribe lists (default:\n"
    "                            /etc/ccomm/signals.xml if it exists; '' for none);\n"
    "                            options given here win over it\n"
    "  -s, --namespace NS        ROS 2 namespace of the topics (default: ccomm; '' or /\n"
    "                            for none)\n"
    "  -d, --domain ID           ROS 2 domain id, 0..232 (default: <ros2 domain=>, else\n"
    "                            $ROS_DOMAIN_ID, else 0)\n"
    "  -p, --publish SIG[,SIG]   signals to publish to ROS 2 (default: every signal this\n"
    "                            node consumes; 'none' for none); repeatable\n"
    "  -S, --subscribe SIG[,SIG] signals produced by this node to take from ROS 2 topics;\n"
    "                            repeatable\n"
    "      --stamp write|arrival DDS source timestamp of a sample: when the producer wrote\n"
    "                            the value, on the boards' common (PTP) time base (default;\n"
    "                            known when both clocks are synced or the producer is this\n"
    "                            node, else the arrival, counted as stamped_local), or\n"
    "                            always the time the value reached this node\n"
    "      --priority N          run the ccomm -> ROS 2 thread SCHED_FIFO at priority N\n"
    "                            (1..99): a state signal changing at 1 kHz needs the bridge\n"
    "                            to read it within 1 ms, or it sees only the newest value\n"
    "      --stats SECONDS       print the counters as one JSON line every SECONDS\n"
    "                            (always on SIGUSR1 and at exit)\n"
    "  -l, --list                print the topics, types and QoS the bridge would use, and exit\n"
    "      --check               validate the configuration (--config FILE, as ccommd --check)\n"
    "                            and its <ros2> sections, print every error as FILE:LINE, and\n"
    "                            exit: 0 valid, 1 not; needs no ccommd\n"
    "  -v, --verbose             more messages on stderr\n"
    "  -h, --help                this text\n"
    "\n"
    "DDS settings (interfaces, discovery peers) come from CYCLONEDDS_URI as for any Cyclone\n"
    "DDS program. Exit status: 0 on SIGINT/SIGTERM, 1 on an error at run time (e.g. a\n"
    "signal's type changed under a new configuration), 2 on a usage error.\n";

void SplitInto(const char* arg, std::vector<std::string>* out) {
  const char* p = arg;
  while (*p) {
    const char* comma = strchr(p, ',');
    size_t n = comma ? static_cast<size_t>(comma - p) : strlen(p);
    if (n) out->emplace_back(p, n);
    p += n + (comma ? 1 : 0);
  }
}

bool ParseDomain(const char* s, const char* what, int* out) {
  char* end = nullptr;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || !*s || *end || v < 0 || v > 232) {
    fprintf(stderr,
            "ccomm-ros2: bad domain '%s' (%s): a ROS 2 domain id is an integer 0..232 "
            "(DDS derives UDP ports from it)\n", s, what);
    return false;
  }
  *out = static_cast<int>(v);
  return true;
}

}  // namespace

int ParseOptions(int argc, char** argv, Options* o) {
  enum { kStamp = 1000, kStats, kPriority, kCheck };
  static const struct option kLong[] = {
      {"node", required_argument, nullptr, 'n'},   {"namespace", required_argument, nullptr, 's'},
      {"domain", required_argument, nullptr, 'd'}, {"publish", required_argument, nullptr, 'p'},
      {"subscribe", required_argument, nullptr, 'S'}, {"stamp", required_argument, nullptr, kStamp},
      {"stats", required_argument, nullptr, kStats},
      {"priority", required_argument, nullptr, kPriority}, {"list", no_argument, nullptr, 'l'},
      {"verbose", no_argument, nullptr, 'v'},      {"help", no_argument, nullptr, 'h'},
      {"config", required_argument, nullptr, 'c'}, {"check", no_argument, nullptr, kCheck},
      {nullptr, 0, nullptr, 0}};
  if (const char* env = getenv("ROS_DOMAIN_ID"); env && *env) {
    if (!ParseDomain(env, "from ROS_DOMAIN_ID", &o->domain)) return 2;
  }
  int ch;
  while ((ch = getopt_long(argc, argv, "n:s:d:p:S:c:lvh", kLong, nullptr)) != -1) {
    switch (ch) {
      case 'n': o->node = optarg; break;
      case 's': o->ros_namespace = optarg; o->namespace_given = true; break;
      case 'd':
        if (!ParseDomain(optarg, "--domain", &o->domain)) return 2;
        o->domain_given = true;
        break;
      case 'c': o->config_path = optarg; o->config_given = true; break;
      case 'p':
        o->publish_given = true;
        if (strcmp(optarg, "none") != 0) SplitInto(optarg, &o->publish);
        break;
      case 'S': SplitInto(optarg, &o->subscribe); break;
      case kStamp:
        if (strcmp(optarg, "write") == 0) o->stamp = StampMode::kWrite;
        else if (strcmp(optarg, "arrival") == 0) o->stamp = StampMode::kArrival;
        else { fprintf(stderr, "ccomm-ros2: --stamp must be 'write' or 'arrival', not '%s'\n", optarg); return 2; }
        break;
      case kStats: {
        char* end = nullptr;
        o->stats_interval_s = strtod(optarg, &end);
        if (*end || !(o->stats_interval_s > 0)) {
          fprintf(stderr, "ccomm-ros2: --stats needs a positive number of seconds, not '%s'\n", optarg);
          return 2;
        }
        break;
      }
      case kPriority: {
        char* end = nullptr;
        long p = strtol(optarg, &end, 10);
        if (*end || p < 1 || p > 99) {
          fprintf(stderr, "ccomm-ros2: --priority must be 1..99 (SCHED_FIFO), not '%s'\n", optarg);
          return 2;
        }
        o->priority = static_cast<int>(p);
        break;
      }
      case 'l': o->list_only = true; break;
      case kCheck: o->check_only = true; break;
      case 'v': ++o->verbose; break;
      case 'h': fputs(kUsage, stdout); return 0;
      default: fputs("Try 'ccomm-ros2 --help'.\n", stderr); return 2;
    }
  }
  if (optind < argc) {
    fprintf(stderr, "ccomm-ros2: unexpected argument '%s' (see --help)\n", argv[optind]);
    return 2;
  }
  if (!o->config_given && access("/etc/ccomm/signals.xml", R_OK) == 0) o->config_path = "/etc/ccomm/signals.xml";
  std::string& ns = o->ros_namespace;  // stored without leading/trailing '/'
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  while (!ns.empty() && ns.back() == '/') ns.pop_back();
  if (!IsRosNamespace(ns)) {
    fprintf(stderr, "ccomm-ros2: --namespace '%s' is not a ROS 2 name (letters, digits, '_', "
                    "'/' between tokens, no token starting with a digit)\n", ns.c_str());
    return 2;
  }
  for (const std::string& s : o->publish)
    for (const std::string& t : o->subscribe)
      if (s == t) {
        fprintf(stderr, "ccomm-ros2: %s is both --publish and --subscribe (it would loop)\n", s.c_str());
        return 2;
      }
  return -1;
}

}  // namespace ccomm_ros2
