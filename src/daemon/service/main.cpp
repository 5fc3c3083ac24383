// SPDX-License-Identifier: Apache-2.0
// ccommd: one per board. Loads signals.xml, creates the node's shared-memory segment,
// forwards signals over raw Ethernet or UDP. Started by systemd (Type=notify).
// The options, the start-up sequence and the main loop; the loop's reload states are
// reloader.h's, the I/O threads io_threads.h's.
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <algorithm>
#include <memory>
#include <string>

#include "common/platform.h"
#include "config/config.h"
#include "config/config_json.h"
#include "daemon/clock/ptp_config.h"
#include "daemon/engine/daemon.h"
#include "daemon/engine/segment_builder.h"
#include "daemon/net/node_identity.h"
#include "daemon/net/transport.h"
#include "daemon/security/privileges.h"
#include "daemon/service/board_net_mode.h"
#include "daemon/service/io_threads.h"
#include "daemon/service/reloader.h"
#include "daemon/service/sd_notify.h"
#include "daemon/service/service.h"
#include "daemon/service/stop_request.h"
#include "daemon/service/switch_request.h"
#include "store/layout.h"
#include "wire/wire.h"

// Hooks for the allocation-counting test (tests/alloc_counter.cpp preloads them);
// weak, so they cost nothing in a normal run.
extern "C" void ccomm_steady_state_begin() __attribute__((weak));
extern "C" void ccomm_steady_state_end() __attribute__((weak));

namespace {

const char kUsage[] =
    "Usage: ccommd [OPTIONS]\n"
    "Forward ccomm signals between this board's shared memory and the network.\n"
    "\n"
    "  -c, --config FILE     configuration (default /etc/ccomm/signals.xml)\n"
    "  -n, --node NAME       this board's node in the file (default: $CCOMM_NODE, else the\n"
    "                        hostname if it names a node, else the node whose mac= or ip= is\n"
    "                        on one of this board's interfaces: one image for every board)\n"
    "      --which-node      print which node this board is, and how it was found; exit\n"
    "      --board-net       at boot, as root (ccomm-board-net.service): find this board's node\n"
    "                        (--node, $CCOMM_NODE, ccomm.node= on the kernel command line, the\n"
    "                        interfaces' MAC, the hostname), set the hostname to its name, bring\n"
    "                        its interface up with its ip= (/24) or DHCP; exit\n"
    "      --dry-run         with --board-net: say what it would do, change nothing\n"
    "      --network-dir DIR with --board-net: where the .network file goes (default\n"
    "                        /run/systemd/network)\n"
    "      --check [FILE]    validate the configuration, print every error as FILE:LINE, exit\n"
    "      --json            with --check: print the resolved configuration as JSON (nodes,\n"
    "                        signals, types, hash, ros2) for tools; docs/config.md\n"
    "      --transport udp   use UDP for every node, whatever the file says (no root needed)\n"
    "      --no-rt           skip mlockall and SCHED_FIFO (tests, unprivileged runs)\n"
    "      --ptp-socket PATH ptp4l's management socket, asked for the clock state once a\n"
    "                        second (default: <clock socket=>, else /var/run/ptp4l; 'none':\n"
    "                        not asked, state none)\n"
    "      --clock-config    print ptp4l's configuration for this node from <clock>; exit\n"
    "      --reload PID      check the file as --check does; if valid, ask the ccommd PID to\n"
    "                        reload it and wait for the result (systemctl reload: ExecReload=);\n"
    "                        exit 0 applied, 1 invalid file or not applied (ccommd keeps running\n"
    "                        on the configuration it had; its log says why)\n"
    "      --at T            with --reload: switch at instant T (seconds since the epoch, up to\n"
    "                        9 decimals; CLOCK_REALTIME) to FILE.staged, checked by ccommd at\n"
    "                        once; cancelled if FILE.staged is removed or changed before T;\n"
    "                        once applied FILE.staged replaces FILE (old: FILE.previous).\n"
    "                        Prints 'armed T', then 'switched T APPLIED' (ns); ccomm deploy's\n"
    "                        second phase (ccomm-deploy(1))\n"
    "  -v, --verbose         more log output (notices about peers and restarts are on by default)\n"
    "  -q, --quiet           warnings and errors only\n"
    "  -h, --help            this text\n"
    "  -V, --version         version\n"
    "\n"
    "Needs: CAP_NET_RAW for raw Ethernet (transport=\"raw\"), CAP_IPC_LOCK for mlockall and\n"
    "CAP_SYS_NICE for SCHED_FIFO (<realtime priority=\"..\"/>); without them ccommd says so and\n"
    "carries on where it can (without RT), or fails with what to do (raw sockets).\n"
    "Environment: CCOMM_SHM_PREFIX (default \"/ccomm.\") names the segment /ccomm.NODE.\n"
    "Signals: SIGTERM/SIGINT stop; SIGHUP reloads the file (docs/usage.md, \"Reload\").\n"
    "Exit status: 0 clean stop or valid config, 1 invalid config, 2 usage, 3 start-up failure.\n"
    "See ccommd(8), docs/config.md and docs/protocol.md.\n";


}  // namespace

// The daemon; main() runs it, as a Windows service with --service (service.h).
int RunDaemon(int argc, char** argv) {
  using namespace ccomm;
  DaemonOptions opt;
  int verbosity = 6;
  static const struct option kLong[] = {
      {"config", required_argument, nullptr, 'c'}, {"node", required_argument, nullptr, 'n'},
      {"check", optional_argument, nullptr, 'C'},  {"transport", required_argument, nullptr, 'T'},
      {"no-rt", no_argument, nullptr, 'R'},        {"verbose", no_argument, nullptr, 'v'},
      {"quiet", no_argument, nullptr, 'q'},        {"help", no_argument, nullptr, 'h'},
      {"version", no_argument, nullptr, 'V'},      {"which-node", no_argument, nullptr, 'W'},
      {"json", no_argument, nullptr, 'J'},
      {"board-net", no_argument, nullptr, 'B'}, {"dry-run", no_argument, nullptr, 'D'},
      {"network-dir", required_argument, nullptr, 'N'},
      {"ptp-socket", required_argument, nullptr, 'P'}, {"clock-config", no_argument, nullptr, 'K'},
      {"reload", required_argument, nullptr, 'L'}, {"at", required_argument, nullptr, 'A'},
      {nullptr, 0, nullptr, 0}};
  bool json = false, board_net = false, dry_run = false;
  int reload_pid = 0;
  uint64_t switch_at_ns = 0;  // --at
  std::string network_dir = "/run/systemd/network";
  bool network_dir_given = false;
  // Under systemd every line gets its priority, also a usage error's (journalctl -p err).
  SetLogPrefixes(platform::StderrIsJournal());
  opterr = 0;
  int ch;
  while ((ch = getopt_long(argc, argv, "c:n:vqhV", kLong, nullptr)) != -1) {
    switch (ch) {
      case 'c': opt.config_path = optarg; break;
      case 'n': opt.node = optarg; break;
      case 'C':
        opt.check_only = true;
        if (optarg) opt.config_path = optarg;
        else if (optind < argc && argv[optind][0] != '-') opt.config_path = argv[optind++];
        break;
      case 'T':
        if (strcmp(optarg, "udp") == 0) opt.force_udp = true;
        else if (strcmp(optarg, "raw") != 0) {
          Log(LogLevel::kError, "ccommd: --transport takes 'udp' or 'raw', not '%s'", optarg);
          return 2;
        }
        break;
      case 'R': opt.no_realtime = true; break;
      case 'P':
        opt.ptp_socket = strcmp(optarg, "none") == 0 ? "" : optarg;
        opt.ptp_socket_given = true;
        break;
      case 'K': opt.clock_config = true; break;
      case 'W': opt.which_node = true; break;
      case 'J': json = true; break;
      case 'L':
        reload_pid = atoi(optarg);
        if (reload_pid <= 0) {
          Log(LogLevel::kError, "ccommd: --reload takes the pid of the running ccommd, not '%s'", optarg);
          return 2;
        }
        break;
      case 'A':
        switch_at_ns = switch_at::ParseInstant(optarg);
        if (!switch_at_ns) {
          Log(LogLevel::kError, "ccommd: --at takes seconds since the epoch (up to 9 decimals: date +%%s.%%N), "
              "not '%s'", optarg);
          return 2;
        }
        break;
      case 'B': board_net = true; break;
      case 'D': dry_run = true; break;
      case 'N':
        network_dir = optarg;
        network_dir_given = true;
        break;
      case 'v': verbosity = verbosity < 7 ? verbosity + 1 : 7; break;
      case 'q': verbosity = 4; break;
      case 'h': fputs(kUsage, stdout); return 0;
      case 'V': printf("ccommd %s (wire v%u, shm layout v%u)\n", CCOMM_VERSION, unsigned{wire::kVersion},
                       store::kLayoutVersion); return 0;
      default:
        // getopt's own message would go out without a priority (opterr = 0 above).
        Log(LogLevel::kError, "ccommd: unknown option or missing argument: '%s'", argv[optind - 1]);
        fputs(kUsage, stderr);
        return 2;
    }
  }
  if (json && !opt.check_only) {
    Log(LogLevel::kError, "ccommd: --json goes with --check");
    return 2;
  }
  if (dry_run && !board_net) {
    Log(LogLevel::kError, "ccommd: --dry-run goes with --board-net");
    return 2;
  }
  if (reload_pid && (board_net || opt.check_only || opt.which_node || opt.clock_config)) {
    Log(LogLevel::kError, "ccommd: --reload goes with none of --board-net, --check, --which-node, --clock-config");
    return 2;
  }
  if (switch_at_ns && !reload_pid) {
    Log(LogLevel::kError, "ccommd: --at goes with --reload PID");
    return 2;
  }
  // The staged file is checked, not the one in place (it may not even exist yet).
  if (switch_at_ns) return switch_at::Request(opt.config_path, reload_pid, switch_at_ns);
  if (board_net && (opt.check_only || opt.which_node || opt.clock_config)) {
    Log(LogLevel::kError, "ccommd: --board-net goes with none of --check, --which-node, --clock-config");
    return 2;
  }
  if (optind < argc) {
    Log(LogLevel::kError, "ccommd: unexpected argument '%s'", argv[optind]);
    fputs(kUsage, stderr);
    return 2;
  }
  SetLogVerbosity(static_cast<LogLevel>(verbosity));

  // The configuration in use; a reload replaces it (reloader.h).
  std::unique_ptr<SystemConfig> cfg_owner(new SystemConfig);
  SystemConfig& cfg = *cfg_owner;
  std::string error;
  if (!LoadConfig(opt.config_path, &cfg, &error)) {
    // Each FILE:LINE line at error priority: these are why the service (or the reload) failed.
    LogText(LogLevel::kError, error);
    if (reload_pid)  // ExecReload=
      Log(LogLevel::kError, "not reloaded: ccommd (pid %d) keeps running on the configuration it has", reload_pid);
    return 1;
  }
  if (reload_pid) {
    // Valid here; the daemon reads and checks it again (the file it uses) and answers.
    const int r = stop::AskReload(reload_pid, 30000);
    if (r == 1) {
      Log(LogLevel::kInfo, "ccommd (pid %d) reloaded %s", reload_pid, opt.config_path.c_str());
      return 0;
    }
    if (r == 0)
      Log(LogLevel::kError, "ccommd (pid %d) did not apply %s and keeps running on the configuration it had: "
          "its log says why", reload_pid, opt.config_path.c_str());
    else
      Log(LogLevel::kError, "cannot ask ccommd (pid %d) to reload: %s", reload_pid,
          r == -ETIMEDOUT ? "no answer within 30 s" : strerror(-r));
    return 1;
  }
  if (opt.check_only && json) {
    fputs(ConfigToJson(cfg).c_str(), stdout);
    return 0;
  }
  if (opt.check_only) {
    // A valid file can still need more shared memory than this machine gives (queue_depth
    // x size adds up): say so now, not with a SIGBUS at start (exit 3, as start would).
    for (uint32_t i = 0; i < cfg.nodes.size(); ++i) {
      const std::string fit = SegmentFitProblem(cfg, i, store::SegmentName(cfg.nodes[i].name));
      if (!fit.empty()) {
        Log(LogLevel::kError, "%s: error: %s", opt.config_path.c_str(), fit.c_str());
        return 3;
      }
    }
    // Where raw Ethernet is not built (Windows), this host's node must use UDP. Which node
    // that is may not be known where the file is checked: then there is nothing to say.
    if (!FindTransport(TransportKind::kRaw) && !opt.force_udp) {
      const char* env = getenv("CCOMM_NODE");
      const std::string name = !opt.node.empty() ? opt.node : env ? env : "";
      char host[64] = "";
      if (!platform::HostName(host, sizeof host)) host[0] = '\0';
      std::string how, why;
      const int n = IdentifyNode(cfg, name, "--node", host, LocalInterfaces(), &how, &why);
      if (n >= 0 && cfg.nodes[static_cast<size_t>(n)].transport == TransportKind::kRaw) {
        const NodeConfig& self = cfg.nodes[static_cast<size_t>(n)];
        Log(LogLevel::kError, "%s:%d: error: %s", opt.config_path.c_str(), self.line,
            RawEthernetUnavailable(self).c_str());
        return 1;
      }
    }
    printf("%s: ok (%zu nodes, %zu signals, hash %08x)\n", opt.config_path.c_str(), cfg.nodes.size(),
           cfg.signals.size(), cfg.hash);
    return 0;
  }
  std::string explicit_from = "--node";
  if (opt.node.empty() && getenv("CCOMM_NODE") && *getenv("CCOMM_NODE")) {
    opt.node = getenv("CCOMM_NODE");
    explicit_from = "$CCOMM_NODE";
  }
  if (board_net) {
    return RunBoardNet(cfg, opt.node, explicit_from.c_str(), dry_run, network_dir, network_dir_given);
  }
  char host[64] = "";
  if (!platform::HostName(host, sizeof host)) host[0] = '\0';
  std::string how, node_error;
  int node = IdentifyNode(cfg, opt.node, explicit_from.c_str(), host, LocalInterfaces(), &how, &node_error);
  // At boot the board's address or hostname may come a little after ccommd starts (DHCP,
  // ccomm-board-net.service without the ordering): look again every 100 ms, the hostname
  // too, for up to 10 s, and go on as soon as one names a node.
  for (int tries = 0; node < 0 && opt.node.empty() && !opt.which_node && tries < 100; ++tries) {
    if (tries == 0) Log(LogLevel::kNotice, "%s; waiting up to 10 s for the board's addresses", node_error.c_str());
    platform::SleepNs(100ull * 1000 * 1000);
    if (!platform::HostName(host, sizeof host)) host[0] = '\0';
    node = IdentifyNode(cfg, opt.node, explicit_from.c_str(), host, LocalInterfaces(), &how, &node_error);
  }
  if (node < 0) {
    Log(LogLevel::kError, "ccommd: %s", node_error.c_str());
    return 1;
  }
  if (opt.which_node) {
    printf("%s (%s)\n", cfg.nodes[static_cast<size_t>(node)].name.c_str(), how.c_str());
    return 0;
  }
  if (opt.clock_config) {
    const std::string text = Ptp4lConfig(cfg, static_cast<uint32_t>(node), &error);
    if (text.empty()) {
      Log(LogLevel::kError, "ccommd: %s", error.c_str());
      return 1;
    }
    fputs(text.c_str(), stdout);
    return 0;
  }
  // <clock socket=> names ptp4l's socket unless --ptp-socket did.
  if (!opt.ptp_socket_given && cfg.clock.present) opt.ptp_socket = cfg.clock.socket;
  opt.node = cfg.nodes[static_cast<size_t>(node)].name;
  Log(LogLevel::kInfo, "this board is node '%s' (%s)", opt.node.c_str(), how.c_str());

  // Stop requests are handled synchronously by the main thread (signals: the I/O threads block them).
  stop::Install();

  const NodeConfig& self = cfg.nodes[static_cast<size_t>(node)];
  if (!opt.no_realtime && self.realtime.mlockall) {
    platform::RealtimeRequest want;
    want.lock_memory = true;
    const int r = platform::SetUpRealtime(want).lock_memory;
    if (r != 0)
      Log(LogLevel::kWarning, "mlockall failed (%s): page faults may add latency; needs CAP_IPC_LOCK or "
          "LimitMEMLOCK=infinity", strerror(-r));
  }

  opt.watchdog_ns = sd::WatchdogIntervalNs();
  // The receive thread's socket timeout: its idle wake-ups, and the watchdog's proof that it turns.
  opt.recv_timeout_ms = IdleRecvTimeoutMs();
  if (opt.watchdog_ns && opt.watchdog_ns / 4000000 < static_cast<uint64_t>(opt.recv_timeout_ms))
    opt.recv_timeout_ms = std::max(1, static_cast<int>(opt.watchdog_ns / 4000000));  // 0 would wait forever
  static Daemon daemon;  // large (frame buffers): not on the stack
  int r = daemon.Start(cfg, static_cast<uint32_t>(node), opt, &error);
  if (r != 0) {
    Log(LogLevel::kError, "ccommd: %s", error.c_str());
    return 3;
  }
  Log(LogLevel::kInfo, "ccommd %s: node '%s', %zu signals, transport %s, segment %s (%s), config hash %08x",
      CCOMM_VERSION, self.name.c_str(), cfg.signals.size(), daemon.transport_name(),
      store::SegmentName(self.name).c_str(), daemon.adopted_segment() ? "re-adopted" : "created", cfg.hash);

  // Socket open, segment created, memory locked: no capability is needed any more. The
  // I/O threads created next inherit the reduced sets (privileges.h).
  std::string privileges;
  r = DropPrivileges(self.realtime, !opt.no_realtime, &privileges);
  if (r != 0) Log(LogLevel::kWarning, "cannot drop capabilities: %s", strerror(-r));
  else Log(LogLevel::kInfo, "%s", privileges.c_str());

  IoThreads io;
  if (StartIo(daemon, &io) != 0) return 3;
  sd::NotifyReady();
  uint32_t node_id = static_cast<uint32_t>(node);
  if (ccomm_steady_state_begin) ccomm_steady_state_begin();

  const uint64_t watchdog_ns = opt.watchdog_ns;
  uint64_t last_ping = 0, last_tx = 0, last_rx = 0;
  Reloader reloader(daemon, opt, std::move(cfg_owner), node_id, &io);
  // Until the supervision's next tick (Supervisor::NextTickNs), rounded up to the ms;
  // with a watchdog, at most a quarter of its interval.
  uint64_t next_tick = platform::MonotonicNs();
  for (;;) {
    const uint64_t before = platform::MonotonicNs();
    uint64_t wait_ns = next_tick > before ? next_tick - before : 0;
    if (watchdog_ns && wait_ns > watchdog_ns / 4) wait_ns = watchdog_ns / 4;
    const stop::Request req = stop::Wait(reloader.WaitMs(static_cast<int>((wait_ns + 999999) / 1000000)));
    if (req == stop::Request::kStop) break;
    if (reloader.Handle(req) == ReloadOutcome::kBroken) {
      daemon.Shutdown();
      return 3;
    }
    uint64_t now = platform::MonotonicNs();
    daemon.Supervise(now);
    next_tick = daemon.NextSupervisionNs();
    // Ping the watchdog only while both I/O loops make progress.
    if (watchdog_ns && now - last_ping >= watchdog_ns / 2) {
      uint64_t t = daemon.tx_loops(), x = daemon.rx_loops();
      if (t != last_tx && x != last_rx) sd::NotifyWatchdog();
      last_tx = t;
      last_rx = x;
      last_ping = now;
    }
  }
  if (ccomm_steady_state_end) ccomm_steady_state_end();
  reloader.Cancel("ccommd stops");
  sd::NotifyStopping();
  Log(LogLevel::kInfo, "stopping");
  StopIo(daemon, &io);
  daemon.Shutdown();
  return 0;
}

int main(int argc, char** argv) { return ccomm::service::Main(argc, argv, RunDaemon); }
