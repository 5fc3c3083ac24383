// SPDX-License-Identifier: Apache-2.0
// ccommd's reload states (reloader.h).
#include "daemon/service/reloader.h"

#include <stdio.h>

#include <algorithm>

#include "daemon/engine/segment_builder.h"
#include "daemon/service/sd_notify.h"
#include "daemon/service/switch_request.h"
#include "store/layout.h"

namespace ccomm {
namespace {

std::string FirstLine(const std::string& text) { return text.substr(0, text.find('\n')); }

// Furthest ahead a switch may be armed: an instant farther away is a mistake, not a plan.
constexpr uint64_t kSwitchHorizonNs = 600ull * 1000000000;

}  // namespace

int Reloader::WaitMs(int tick_ms) const {
  if (!armed_.cfg) return tick_ms;
  const uint64_t t = platform::RealtimeNs();
  if (armed_.at_ns <= t) return 0;
  return std::min(tick_ms, static_cast<int>(std::min<uint64_t>(10, (armed_.at_ns - t) / 1000000)));
}

ReloadOutcome Reloader::Handle(stop::Request req) {
  ReloadOutcome outcome = ReloadOutcome::kRefused;
  if (req == stop::Request::kReload) {
    Cancel("a reload was asked for");
    outcome = ReloadNow();
  } else if (req == stop::Request::kReloadAt) {
    Arm();
  }
  if (armed_.cfg && platform::RealtimeNs() >= armed_.at_ns) outcome = Fire();
  return outcome;
}

std::string Reloader::Problem(const std::string& path, std::unique_ptr<SystemConfig>* next, uint32_t* n) const {
  next->reset(new SystemConfig);
  std::string error;
  if (!LoadConfig(path, next->get(), &error)) return error;
  const int i = (*next)->FindNode(opt_.node);
  if (i < 0)
    return path + ": error: this board's node '" + opt_.node +
           "' is not in the file any more (restart ccommd to be another node)";
  *n = static_cast<uint32_t>(i);
  const std::string why = daemon_.ReloadRefusal(**next, *n);
  if (!why.empty()) return why;
  const std::string fit = SegmentFitProblem(**next, *n, store::SegmentName(opt_.node));
  if (!fit.empty()) return path + ": error: " + fit;
  return "";
}

ReloadOutcome Reloader::Refuse(int requester, const std::string& why) const {
  LogText(LogLevel::kError, why);
  Log(LogLevel::kError, "reload failed: still forwarding on the configuration loaded before (hash %08x)", cfg_->hash);
  const std::string status = "forwarding on the old configuration; reload failed: " + FirstLine(why);
  sd::NotifyReloaded(status.c_str());
  stop::AnswerReload(requester, stop::ReloadAnswer::kRefused);
  return ReloadOutcome::kRefused;
}

ReloadOutcome Reloader::Apply(std::unique_ptr<SystemConfig>* next, uint32_t n, int requester, int64_t late_ns) {
  std::string error;
  const uint64_t t0 = platform::MonotonicNs();
  StopIo(daemon_, io_);
  int r = daemon_.Reconfigure(**next, n, &error);
  if (r != 0) {
    const std::string failed = error;
    Log(LogLevel::kError, "reload: %s; setting the configuration before up again", failed.c_str());
    error.clear();
    if (daemon_.Reconfigure(*cfg_, node_, &error) != 0 || StartIo(daemon_, io_) != 0) {
      Log(LogLevel::kError, "reload: cannot set the configuration before up again either (%s): exiting",
          error.c_str());
      return ReloadOutcome::kBroken;
    }
    return Refuse(requester, opt_.config_path + ": error: " + failed);
  }
  if (StartIo(daemon_, io_) != 0) return ReloadOutcome::kBroken;
  const double paused_ms = static_cast<double>(platform::MonotonicNs() - t0) / 1e6;
  const bool signals_changed = (*next)->hash != cfg_->hash;
  std::string when;
  if (late_ns >= 0) {
    char late[48];
    snprintf(late, sizeof late, "%.1f ms)", static_cast<double>(late_ns) / 1e6);
    when = " (from " + switch_at::StagedPath(opt_.config_path) + ", at the agreed instant + " + late;
  }
  Log(LogLevel::kNotice, "reloaded %s%s: %zu signals, config hash %08x%s; segment %s; forwarding paused %.1f ms",
      opt_.config_path.c_str(), when.c_str(), (*next)->signals.size(), (*next)->hash,
      signals_changed ? " (changed)" : " (same)",
      daemon_.adopted_segment() ? "kept (same layout)" : "replaced (the old one retired: applications reopen)",
      paused_ms);
  cfg_.swap(*next);  // the parts now read cfg_; the old configuration goes
  next->reset();
  node_ = n;
  sd::NotifyReloaded("forwarding");
  stop::AnswerReload(requester, stop::ReloadAnswer::kApplied);
  return ReloadOutcome::kApplied;
}

ReloadOutcome Reloader::ReloadNow() {
  const int requester = stop::ReloadRequester();
  sd::NotifyReloading();
  Log(LogLevel::kNotice, "reload: reading %s", opt_.config_path.c_str());
  std::unique_ptr<SystemConfig> next;
  uint32_t n = 0;
  const std::string why = Problem(opt_.config_path, &next, &n);
  if (!why.empty()) return Refuse(requester, why);
  return Apply(&next, n, requester, -1);
}

void Reloader::Cancel(const char* why) {
  if (!armed_.cfg) return;
  Log(LogLevel::kError, "reload: the switch to %s is cancelled: %s; still forwarding on the configuration it has",
      armed_.cfg->path.c_str(), why);
  stop::AnswerReload(armed_.requester, stop::ReloadAnswer::kRefused);
  armed_.cfg.reset();
}

void Reloader::Arm() {
  Cancel("a newer switch was asked for");
  const int requester = stop::ReloadRequester();
  const std::string staged = switch_at::StagedPath(opt_.config_path);
  std::string why;
  const uint64_t at = switch_at::ReadInstant(opt_.config_path, &why);
  const uint64_t now = platform::RealtimeNs();
  if (at && at <= now) why = "the switch instant is already " + std::to_string((now - at) / 1000000) + " ms past";
  if (at && at > now + kSwitchHorizonNs) why = "the switch instant is more than 10 minutes ahead";
  if (!at || !why.empty()) {
    Refuse(requester, switch_at::InstantPath(opt_.config_path) + ": error: " + why);
    return;
  }
  const platform::FileIdentity id = platform::IdentifyFile(staged.c_str());
  uint32_t n = 0;
  why = Problem(staged, &armed_.cfg, &n);
  if (!why.empty()) {
    armed_.cfg.reset();
    Refuse(requester, why);
    return;
  }
  armed_.node = n;
  armed_.at_ns = at;
  armed_.requester = requester;
  armed_.staged = id;
  Log(LogLevel::kNotice, "reload: %s checked (%zu signals, config hash %08x); switching to it in %.3f s",
      staged.c_str(), armed_.cfg->signals.size(), armed_.cfg->hash, static_cast<double>(at - now) / 1e9);
  stop::AnswerReload(requester, stop::ReloadAnswer::kArmed);
}

ReloadOutcome Reloader::Fire() {
  const int64_t late = static_cast<int64_t>(platform::RealtimeNs() - armed_.at_ns);
  if (!platform::SameFile(armed_.staged,
                          platform::IdentifyFile(switch_at::StagedPath(opt_.config_path).c_str()))) {
    Cancel("the staged file was removed or changed since it was checked (ccomm deploy aborted)");
    return ReloadOutcome::kRefused;
  }
  sd::NotifyReloading();
  const ReloadOutcome r = Apply(&armed_.cfg, armed_.node, armed_.requester, late);
  armed_.cfg.reset();
  return r;
}

}  // namespace ccomm
