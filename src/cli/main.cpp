// SPDX-License-Identifier: Apache-2.0
// ccomm: command-line access to a node's signals (list, echo, pub, stats, gen).
#include <ctype.h>
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "ccomm/ccomm.h"
#include "cli/values.h"
#include "common/public/platform_app.h"

namespace {

const char kUsage[] =
    "Usage: ccomm [--node NAME] COMMAND [ARGS]\n"
    "Inspect and drive the signals of this board's ccommd (shared memory, no root needed\n"
    "if you are in the 'ccomm' group).\n"
    "\n"
    "Commands:\n"
    "  list                     every signal: type, kind, producer, status, age, value\n"
    "  echo SIGNAL [-n N] [--timeout SEC] [--once] [--interval MS]\n"
    "                           print new values/events as they arrive (N of them; default\n"
    "                           until Ctrl-C); --once prints the current value and status;\n"
    "                           --interval prints value and status every MS, changed or not\n"
    "  pub SIGNAL VALUE... [--rate HZ] [--count N]\n"
    "                           write a value (arrays: one value per element, or one for all);\n"
    "                           with --rate, repeat N times (default 1) at HZ (never faster)\n"
    "  stats [--all] [--json] [--watch SEC]\n"
    "                           daemon, peer and signal counters: rates, loss, staleness;\n"
    "                           --all: every node of the system (alive, the peers it hears,\n"
    "                           its counters, per signal rate/loss/staleness/age), from the\n"
    "                           summaries the nodes exchange every <network summary_ms>\n"
    "  gen 20sim4c SIGNALS.XML [NODE] OUTDIR\n"
    "                           generate the 20-sim 4C I/O component for NODE (default: -n)\n"
    "  record, replay, web, ros2, deploy ...\n"
    "                           run the installed tool ccomm-COMMAND (see its --help):\n"
    "                           MCAP recording and replay, live view, ROS 2 bridge,\n"
    "                           one signals.xml onto every board, switched at one instant\n"
    "\n"
    "Options:\n"
    "  -n, --node NAME          node to attach to (default: $CCOMM_NODE, else hostname)\n"
    "  -h, --help               this text\n"
    "\n"
    "Exit status: 0 ok; 1 error; 2 usage; 3 echo timed out before N values.\n"
    "Status words: fresh, stale (older than stale_after_ms; '*' marks a safe value), never\n"
    "(nothing received yet), empty (event signal, nothing new).\n";

volatile sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

const char* StatusWord(int s) {
  switch (s) {
    case CCOMM_FRESH: return "fresh";
    case CCOMM_STALE: return "stale";
    case CCOMM_NEVER: return "never";
    case CCOMM_EMPTY: return "empty";
    default: return "error";
  }
}

int Open(const char* node, ccomm_client** c) {
  int r = ccomm_open(node, 0, c);
  if (r != 0) {
    std::string name = node ? node : (getenv("CCOMM_NODE") ? getenv("CCOMM_NODE") : "(hostname)");
    fprintf(stderr, "ccomm: cannot attach to node %s: %s\n", name.c_str(), ccomm_strerror(r));
    if (r == CCOMM_E_SYS) fprintf(stderr, "ccomm: %s (are you in the 'ccomm' group?)\n", strerror(errno));
    return 1;
  }
  return 0;
}

ccomm_signal Find(ccomm_client* c, const char* name, ccomm_signal_desc* d) {
  ccomm_signal s = ccomm_find(c, name);
  if (s < 0) {
    fprintf(stderr, "ccomm: no signal '%s' on node %s (see: ccomm list)\n", name, ccomm_node_name(c));
    return s;
  }
  ccomm_describe(c, s, d);
  return s;
}

int CmdList(ccomm_client* c) {
  printf("%-4s %-24s %-12s %-6s %-10s %-6s %10s  %s\n", "ID", "NAME", "TYPE", "KIND", "PRODUCER", "STATUS",
         "AGE_MS", "VALUE");
  std::vector<uint8_t> buf;
  for (int i = 0; i < ccomm_signal_count(c); ++i) {
    ccomm_signal_desc d;
    ccomm_describe(c, i, &d);
    char type[32];
    if (d.count == 1) snprintf(type, sizeof type, "%s", ccomm::cli::TypeName(d.type));
    else snprintf(type, sizeof type, "%s[%u]", ccomm::cli::TypeName(d.type), d.count);
    std::string value = "-", status = d.is_event ? "event" : "-";
    char age[32] = "-";
    if (!d.is_event) {
      buf.assign(d.value_bytes, 0);
      ccomm_info info;
      int r = ccomm_read(c, i, buf.data(), buf.size(), &info);
      status = r >= 0 ? StatusWord(r) : ccomm_strerror(r);
      if (r >= 0 && (info.flags & CCOMM_INFO_SAFE_VALUE)) {
        status += "*";  // the value shown is the configured safe value
        value = ccomm::cli::FormatValue(d, buf.data());
      }
      if (r == CCOMM_FRESH || r == CCOMM_STALE) {
        value = ccomm::cli::FormatValue(d, buf.data());
        snprintf(age, sizeof age, "%.1f", static_cast<double>(info.age_ns) / 1e6);
      }
    }
    printf("%-4d %-24s %-12s %-6s %-10s %-6s %10s  %s\n", i, d.name, type, d.is_event ? "event" : "state",
           d.producer, status.c_str(), age, value.c_str());
  }
  return 0;
}

int CmdEcho(ccomm_client* c, int argc, char** argv) {
  long count = -1;
  double timeout = -1;
  bool once = false;
  long interval_ms = 0;
  static const struct option kLong[] = {{"count", required_argument, nullptr, 'n'},
                                        {"interval", required_argument, nullptr, 'i'},
                                        {"timeout", required_argument, nullptr, 't'},
                                        {"once", no_argument, nullptr, 'o'},
                                        {nullptr, 0, nullptr, 0}};
  optind = 0;  // 0: GNU getopt fully re-initialises (1 keeps stale permutation state)
  int ch;
  while ((ch = getopt_long(argc, argv, "n:t:", kLong, nullptr)) != -1) {
    double v = 0;
    if (ch == 'o') {
      once = true;
      continue;
    }
    if (ch != 'n' && ch != 't' && ch != 'i') return 2;
    // --timeout is seconds (decimal, 0 allowed); --count and --interval whole numbers > 0
    if (!ccomm::cli::ParseOptionNumber(optarg, ch != 't', ch == 't', &v)) {
      fprintf(stderr, "ccomm echo: %s needs a %s, not '%s'\n",
              ch == 'n' ? "--count" : ch == 't' ? "--timeout" : "--interval",
              ch == 't' ? "number of seconds >= 0" : "whole number > 0", optarg);
      return 2;
    }
    if (ch == 'n') count = static_cast<long>(v);
    else if (ch == 't') timeout = v;
    else interval_ms = static_cast<long>(v);
  }
  if (optind != argc - 1) {
    fprintf(stderr, "ccomm echo: give exactly one SIGNAL\n");
    return 2;
  }
  ccomm_signal_desc d;
  ccomm_signal s = Find(c, argv[optind], &d);
  if (s < 0) return 1;
  std::vector<uint8_t> buf(d.value_bytes);
  uint64_t start = static_cast<uint64_t>(ccomm_now()), last_seq = 0;
  long printed = 0;
  bool first = true;
  while (!g_stop && (count < 0 || printed < count)) {
    ccomm_info info;
    int r = ccomm_read(c, s, buf.data(), buf.size(), &info);
    if (r < 0) {
      fprintf(stderr, "ccomm echo: %s\n", ccomm_strerror(r));
      return 1;
    }
    bool show = once || interval_ms > 0 || (d.is_event ? r == CCOMM_FRESH : (r != CCOMM_NEVER && (first || info.seq != last_seq)));
    if (show) {
      printf("%s %s %s%s seq=%" PRIu64 " age_us=%" PRId64 " lost=%" PRIu64 "\n", d.name,
             (r == CCOMM_NEVER || r == CCOMM_EMPTY) && !(info.flags & CCOMM_INFO_SAFE_VALUE)
                 ? "-" : ccomm::cli::FormatValue(d, buf.data()).c_str(),
             StatusWord(r), (info.flags & CCOMM_INFO_SAFE_VALUE) ? "*" : "", info.seq,
             info.age_ns >= 0 ? info.age_ns / 1000 : -1, info.lost);
      fflush(stdout);
      last_seq = info.seq;
      first = false;
      printed++;
      if (once) return 0;
      if (d.is_event && interval_ms <= 0) continue;  // drain queued events before waiting
    }
    if (timeout >= 0 && (static_cast<uint64_t>(ccomm_now()) - start) / 1e9 > timeout) break;
    if (interval_ms > 0) {
      ccomm::platform::SleepNsInterruptible(static_cast<uint64_t>(interval_ms) * 1000000u);
    } else {
      ccomm_wait(c, 100);
    }
  }
  // 3 only for --timeout (ccomm(1), EXIT STATUS); ^C or SIGTERM before N values is a normal stop
  return (count >= 0 && printed < count && !g_stop) ? 3 : 0;
}

int CmdPub(ccomm_client* c, int argc, char** argv) {
  double rate = 0;
  long count = 1;
  // Options may come anywhere; words that are numbers ("-1.5", "-inf") are values, not options.
  std::vector<char*> pos;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    bool opt_rate = a == "--rate" || a == "-r" || a.rfind("--rate=", 0) == 0;
    bool opt_count = a == "--count" || a == "-n" || a.rfind("--count=", 0) == 0;
    if (opt_rate || opt_count) {
      size_t eq = a.find('=');
      if (eq == std::string::npos && i + 1 >= argc) {
        fprintf(stderr, "ccomm pub: %s needs a value\n", a.c_str());
        return 2;
      }
      const char* text = eq == std::string::npos ? argv[++i] : argv[i] + eq + 1;
      double v = 0;
      if (!ccomm::cli::ParseOptionNumber(text, opt_count, false, &v)) {
        fprintf(stderr, "ccomm pub: %s needs a %s, not '%s'\n", opt_rate ? "--rate" : "--count",
                opt_rate ? "positive number" : "whole number > 0", text);
        return 2;
      }
      if (opt_rate) rate = v;
      else count = static_cast<long>(v);
    } else if (a.size() > 1 && a[0] == '-' && !ccomm::cli::LooksLikeNumber(argv[i])) {
      fprintf(stderr, "ccomm pub: unknown option '%s'\n", a.c_str());
      return 2;
    } else {
      pos.push_back(argv[i]);
    }
  }
  if (pos.size() < 2) {
    fprintf(stderr, "ccomm pub: give SIGNAL and VALUE...\n");
    return 2;
  }
  ccomm_signal_desc d;
  ccomm_signal s = Find(c, pos[0], &d);
  if (s < 0) return 1;
  std::vector<uint8_t> buf(d.value_bytes);
  std::string err;
  if (!ccomm::cli::ParseValue(d, static_cast<int>(pos.size() - 1), pos.data() + 1, buf.data(), &err)) {
    fprintf(stderr, "ccomm pub: %s: %s\n", d.name, err.c_str());
    return 1;
  }
  int64_t next = ccomm_now();
  const int64_t period_ns = rate > 0 ? static_cast<int64_t>(1e9 / rate) : 0;
  for (long i = 0; i < count && !g_stop; ++i) {
    int r = ccomm_write(c, s, buf.data(), buf.size());
    if (r == CCOMM_E_FULL && ccomm_daemon_alive(c)) {  // the library's text blames a stopped ccommd
      fprintf(stderr, "ccomm pub: %s: event queue full after %ld writes: ccommd has not sent the earlier "
              "events yet (queue_depth in signals.xml; --rate spaces the writes)\n", d.name, i);
      return 1;
    }
    if (r != 0) {
      fprintf(stderr, "ccomm pub: %s: %s\n", d.name, ccomm_strerror(r));
      return 1;
    }
    if (period_ns && i + 1 < count) {
      next += period_ns;
      ccomm::platform::SleepUntilNs(next);
      // Woken a period late or more (a stalled machine): go on from now, never in a burst
      // that would exceed HZ (readers and rate figures see what --rate promised).
      const int64_t now = ccomm_now();
      if (now - next >= period_ns) next = now;
    }
  }
  // Stored, but a segment outlives its ccommd: say that nothing leaves the board now.
  if (!ccomm_daemon_alive(c))
    fprintf(stderr, "ccomm pub: warning: no ccommd is running for node %s: %s stored for this board's readers, "
            "not sent to other nodes until ccommd runs (systemctl start ccommd)\n", ccomm_node_name(c),
            d.is_event ? "the event is queued" : "the value is");
  return 0;
}

}  // namespace

int CmdStats(ccomm_client* c, const char* node, int argc, char** argv);  // stats.cpp
// Other programs (external_posix.cpp, external_windows.cpp).
int RunGenerator(const char* node, std::string path, int argc, char** argv);

// `ccomm gen 20sim4c ...`: the generator is a Python script installed with the
// integrations; the platform part runs it.
int CmdGen(const char* node, int argc, char** argv) {
  if (argc < 2 || strcmp(argv[1], "20sim4c") != 0) {
    fprintf(stderr, "ccomm gen: only '20sim4c' is known\n");
    return 2;
  }
  const char* gen = getenv("CCOMM_GEN_20SIM4C");
  return RunGenerator(node, gen ? gen : CCOMM_DATADIR "/integrations/20sim/4c/gen_4c.py", argc, argv);
}
int RunExternal(const char* node, const char* cmd, int argc, char** argv, const char* usage);

namespace {
// The tools that ship elsewhere say where they come from (nullptr: not one of them).
const char* MissingToolHint(const char* cmd) {
  return !strcmp(cmd, "ros2") ? "ccomm-ros2 is built when Cyclone DDS is found (Debian: cyclonedds-dev, cyclonedds-tools)"
         : (!strcmp(cmd, "record") || !strcmp(cmd, "replay")) ? "it comes with the Python package: pip install 'ccomm[record]'"
         : !strcmp(cmd, "web") ? "it comes with the Python package: pip install 'ccomm[web]'"
         : !strcmp(cmd, "deploy") ? "it comes with the Python package: pip install ccomm"
         : nullptr;
}
}  // namespace

// Why `ccomm CMD` could not run PROG (err: the errno of the exec or spawn), as exit status.
int CannotRun(const char* cmd, const char* prog, int err, const char* usage) {
  if (err == ENOENT) {
    if (const char* hint = MissingToolHint(cmd)) {
      fprintf(stderr, "ccomm: %s is not installed (no %s in PATH): %s\n", cmd, prog, hint);
      return 1;
    }
    fprintf(stderr, "ccomm: unknown command '%s' (no %s in PATH)\n%s", cmd, prog, usage);
    return 2;
  }
  fprintf(stderr, "ccomm: cannot run %s: %s\n", prog, strerror(err));
  return 1;
}

int main(int argc, char** argv) {
  const char* node = nullptr;
  static const struct option kLong[] = {{"node", required_argument, nullptr, 'n'},
                                        {"help", no_argument, nullptr, 'h'},
                                        {nullptr, 0, nullptr, 0}};
  int ch;
  while ((ch = getopt_long(argc, argv, "+n:h", kLong, nullptr)) != -1) {
    if (ch == 'n') node = optarg;
    else if (ch == 'h') { fputs(kUsage, stdout); return 0; }
    else { fputs(kUsage, stderr); return 2; }
  }
  if (optind >= argc) {
    fputs(kUsage, stderr);
    return 2;
  }
  signal(SIGINT, OnSignal);
  signal(SIGTERM, OnSignal);
  const char* cmd = argv[optind];
  int sub_argc = argc - optind;
  char** sub_argv = argv + optind;
  if (strcmp(cmd, "gen") == 0) return CmdGen(node, sub_argc, sub_argv);
  if (strcmp(cmd, "help") == 0) { fputs(kUsage, stdout); return 0; }
  if (strcmp(cmd, "list") && strcmp(cmd, "echo") && strcmp(cmd, "pub") && strcmp(cmd, "stats")) {
    return RunExternal(node, cmd, sub_argc, sub_argv, kUsage);
  }
  // `ccomm echo --help` prints help; it does not need (or try to reach) a daemon.
  for (int i = 1; i < sub_argc; ++i) {
    if (!strcmp(sub_argv[i], "-h") || !strcmp(sub_argv[i], "--help")) {
      fputs(kUsage, stdout);
      return 0;
    }
  }
  if (strcmp(cmd, "list") == 0 && sub_argc > 1) {
    fprintf(stderr, "ccomm list: takes no arguments, not '%s'\n", sub_argv[1]);
    return 2;
  }
  ccomm_client* c = nullptr;
  if (Open(node, &c) != 0) return 1;
  int r = 2;
  if (strcmp(cmd, "list") == 0) r = CmdList(c);
  else if (strcmp(cmd, "echo") == 0) r = CmdEcho(c, sub_argc, sub_argv);
  else if (strcmp(cmd, "pub") == 0) r = CmdPub(c, sub_argc, sub_argv);
  else if (strcmp(cmd, "stats") == 0) r = CmdStats(c, node, sub_argc, sub_argv);
  ccomm_close(c);
  return r;
}
