// SPDX-License-Identifier: Apache-2.0
// Send on the cycle in ccommd (send_cycle.h): the send part's start-up and send-thread
// steps (send_path.h) and the supervision tick's (supervisor.h), over the SendCycle the
// two share (thread_handoffs.h).
#include <errno.h>
#include <string.h>

#include "common/platform.h"
#include "daemon/engine/send_path.h"
#include "daemon/engine/supervisor.h"

namespace ccomm {

// Start-up, after the transport is open and before the capabilities go (SO_TXTIME on
// CLOCK_TAI needs CAP_NET_ADMIN at that call).
void SendPath::StartCycle() {
  const RealtimeConfig& rt = cfg_->nodes[self_].realtime;
  SendCycleConfig c;
  c.cycle_ns = uint64_t{rt.send_cycle_us} * 1000;
  c.phase_ns = uint64_t{rt.send_phase_us} * 1000;
  c.lead_ns = uint64_t{rt.send_lead_us} * 1000;
  c.launch_time = rt.launch_time;
  SendCycle& cycle = ctx_.handoffs.send_cycle;
  cycle.Configure(c);
  if (!cycle.enabled() || !ctx_.transport.ops) return;
  TxtimeProbe probe;
  probe.want = c.launch_time;
  probe.lead_ns = c.lead_ns;
  std::string detail = "not probed";
  if (ctx_.transport.ops->txtime_setup) ctx_.transport.ops->txtime_setup(&ctx_.transport, &probe, &detail);
  ctx_.handoffs.tai_minus_realtime_ns = probe.tai_minus_realtime_ns;
  const LaunchMode mode = SendCycle::Decide(c, probe);
  cycle.SetMode(mode);
  ctx_.segment.header()->daemon_counters[store::kCycleLaunch].store(static_cast<uint64_t>(mode), std::memory_order_relaxed);
  // Every frame of a socket with launch times needs one (ETF drops the others): those not
  // on the cycle (events, heartbeats, summaries) leave this long after they are sent.
  if (mode == LaunchMode::kTxtime) ctx_.transport.txtime_asap_ns = probe.etf_delta_ns + 50000;
  cycle_margin_ns_ = probe.etf_delta_ns + 20000;
  cycle.SetClock(false, ctx_.handoffs.TaiMinusMonotonicNs());
  const char* why = mode == LaunchMode::kSleepRefused ? strerror(probe.socket_error) : "";
  Log(mode == LaunchMode::kTxtime || mode == LaunchMode::kSleepConfigured ? LogLevel::kNotice : LogLevel::kWarning,
      "send cycle %u us, phase %u us, lead %u us, aligned on CLOCK_MONOTONIC until the clock is synced: %s%s%s "
      "[%s]%s",
      rt.send_cycle_us, rt.send_phase_us, rt.send_lead_us, LaunchModeName(mode), *why ? ": " : "", why, detail.c_str(),
      mode == LaunchMode::kSleepRefused && probe.socket_error == EPERM
          ? " (SO_TXTIME on CLOCK_TAI needs CAP_NET_ADMIN when ccommd starts: docs/usage.md, \"Send on the cycle\")"
          : mode == LaunchMode::kSleepNoEtf ? " (set up the ETF qdisc: docs/usage.md, \"Send on the cycle\")" : "");
}

int64_t ThreadHandoffs::TaiMinusMonotonicNs() const {
  // The kernel's TAI offset over CLOCK_REALTIME is whole seconds (read at start-up by the
  // transport; 0 on Windows): realtime - monotonic plus that.
  return platform::RealtimeOffsetNs() + tai_minus_realtime_ns;
}

// Supervision tick: the alignment clock follows this board's sync state; ETF drops are
// counted and logged (at most every 10 s).
void Supervisor::SuperviseSendCycle(uint64_t now, bool synced) {
  SendCycle& cycle = ctx_.handoffs.send_cycle;
  if (!cycle.enabled()) return;
  if (cycle.SetClock(synced, ctx_.handoffs.TaiMinusMonotonicNs()))
    Log(LogLevel::kNotice, "send cycle aligned on %s now (clock %s)",
        cycle.clock() == CycleClock::kTai ? "CLOCK_TAI" : "CLOCK_MONOTONIC", synced ? "synced" : "not synced");
  if (!ctx_.transport.ops || !ctx_.transport.ops->txtime_drops || !cycle.txtime()) return;
  const uint32_t drops = ctx_.transport.ops->txtime_drops(&ctx_.transport);
  if (drops) ctx_.segment.header()->daemon_counters[store::kCycleEtfDrops].fetch_add(drops, std::memory_order_relaxed);
  const uint64_t total = ctx_.segment.header()->daemon_counters[store::kCycleEtfDrops].load(std::memory_order_relaxed);
  if (total != etf_drops_logged_ && now >= etf_drops_next_log_ns_) {
    Log(LogLevel::kWarning, "the ETF qdisc dropped %llu frame(s) (launch time missed or invalid): send_lead_us "
        "too short for this board, or the qdisc's delta", static_cast<unsigned long long>(total - etf_drops_logged_));
    etf_drops_logged_ = total;
    etf_drops_next_log_ns_ = now + 10000000000ull;
  }
}

// Send thread: the periodic signals on the grid of the current alignment clock (at start
// and after it switched), each at its first instant still reachable.
void SendPath::PlaceOnCycle(uint64_t now) {
  const SendCycle& cycle = ctx_.handoffs.send_cycle;
  cycle_generation_ = cycle.generation();
  for (uint32_t id : periodic_) due_ns_[id] = cycle.Place(now, uint64_t{cfg_->signals[id].period_us} * 1000);
}

// Send thread, before a round's frames go out: launch time `instant`, or sleep until it.
void SendPath::CycleRound(uint64_t instant) {
  const SendCycle& cycle = ctx_.handoffs.send_cycle;
  const uint64_t now = platform::MonotonicNs();
  store::SegmentHeader* h = ctx_.segment.header();
  if (cycle.txtime()) {
    if (instant > now + cycle_margin_ns_) {
      flush_launch_tai_ = cycle.LaunchTai(instant);
      h->daemon_counters[store::kCycleRounds].fetch_add(1, std::memory_order_relaxed);
    } else {
      h->daemon_counters[store::kCycleLate].fetch_add(1, std::memory_order_relaxed);  // as soon as ETF can
    }
    return;
  }
  if (instant <= now) {
    h->daemon_counters[store::kCycleLate].fetch_add(1, std::memory_order_relaxed);
    return;
  }
  // At most one lead: a doorbell meanwhile waits for this round's frames. The sleep's
  // remainder (it may end early) is spun, bounded.
  platform::SleepNs(instant - now);
  for (int spin = 0; spin < 100000 && platform::MonotonicNs() < instant; ++spin) platform::CpuRelax();
  h->daemon_counters[store::kCycleRounds].fetch_add(1, std::memory_order_relaxed);
}

}  // namespace ccomm
