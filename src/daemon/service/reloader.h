// SPDX-License-Identifier: Apache-2.0
// ccommd's reload states (docs/usage.md, "Reload" and "Deploy to every board"), on the
// main thread: the configuration in use, and a switch armed for an instant. A reload
// (SIGHUP, systemctl reload) reads and checks the file by the one parser while the I/O
// threads run on; a switch at an instant (switch_request.h: ccomm deploy's second phase)
// is read and checked when asked and applied at the instant, unless its file went away.
// Only a file that can be applied stops the I/O threads, for as long as
// Daemon::Reconfigure takes; every outcome is answered to the requester (stop_request.h)
// and told to the service manager (sd_notify.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "common/platform.h"
#include "config/config.h"
#include "daemon/engine/daemon.h"
#include "daemon/service/io_threads.h"
#include "daemon/service/stop_request.h"

namespace ccomm {

enum class ReloadOutcome {
  kApplied,  // the new configuration runs
  kRefused,  // nothing changed (or nothing was asked): the old one runs on
  kBroken,   // neither the new nor the old configuration could be set up again: exit 3
};

class Reloader {
 public:
  /// `cfg`: the configuration `daemon` runs as node `node`; `io`: its I/O threads (running).
  Reloader(Daemon& daemon, const DaemonOptions& opt, std::unique_ptr<SystemConfig> cfg, uint32_t node,
           IoThreads* io)
      : daemon_(daemon), opt_(opt), cfg_(std::move(cfg)), node_(node), io_(io) {}
  Reloader(const Reloader&) = delete;
  Reloader& operator=(const Reloader&) = delete;

  /// How long the main loop may wait for the next request: `tick_ms` (until the next
  /// supervision tick), or less up to an armed switch's instant (then it is met to the ms).
  int WaitMs(int tick_ms) const;
  /// After stop::Wait returned `req` (not kStop; kNone too): a reload, or a switch armed,
  /// and then a switch whose instant has come.
  ReloadOutcome Handle(stop::Request req);
  /// An armed switch is dropped (its requester told why); nothing else changes.
  void Cancel(const char* why);

 private:
  // A switch at an instant, armed: checked, waiting for at_ns.
  struct Armed {
    std::unique_ptr<SystemConfig> cfg;
    uint32_t node = 0;
    uint64_t at_ns = 0;  // CLOCK_REALTIME
    int requester = 0;
    platform::FileIdentity staged;
  };

  /// Why `path` cannot be the next configuration ("" if it can: then *next and *n are set).
  std::string Problem(const std::string& path, std::unique_ptr<SystemConfig>* next, uint32_t* n) const;
  ReloadOutcome Refuse(int requester, const std::string& why) const;
  /// Puts `next` (checked by Problem) in place of the running configuration. `late_ns` >= 0:
  /// a switch at an instant, begun that long after it.
  ReloadOutcome Apply(std::unique_ptr<SystemConfig>* next, uint32_t n, int requester, int64_t late_ns);
  ReloadOutcome ReloadNow();  // SIGHUP
  void Arm();                 // kReloadAt: read and check CONFIG.staged now, answer "armed"
  ReloadOutcome Fire();       // at the instant

  Daemon& daemon_;
  const DaemonOptions& opt_;
  std::unique_ptr<SystemConfig> cfg_;  // the configuration in use (the parts read it)
  uint32_t node_;
  IoThreads* io_;
  Armed armed_;
};

}  // namespace ccomm
