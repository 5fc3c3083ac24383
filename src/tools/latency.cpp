// SPDX-License-Identifier: Apache-2.0
// ccomm-latency: a control-loop-shaped load and latency probe, app -> ccommd -> wire ->
// ccommd -> app. Used by scripts/demo, scripts/bench and the QEMU tests.
//
// Each cycle (platform::SleepUntilNs, absolute) the sender writes every --send signal with the
// cycle number k as value, then ccomm_flush(): one frame per cycle. A receive thread
// blocks in ccomm_wait() and records, for each cycle whose --recv signals have all
// arrived, the latency:
//   oneway: arrival - producer's write time (same clock: namespaces on one host)
//   ping:   the peer runs --mode echo and sends k back; RTT/2 = (arrival - send of k)/2
// Loss = cycles in the observed range that never arrived complete.
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <string>
#include <vector>

#include "ccomm/ccomm.h"
#include "common/public/platform_app.h"
#include "tools/json_text.h"

namespace {

const char kUsage[] =
    "Usage: ccomm-latency [OPTIONS]\n"
    "Sends doubles at a fixed rate through ccomm and measures the latency of what comes back.\n"
    "  -n, --node NAME        node to attach to (default $CCOMM_NODE / hostname)\n"
    "  -r, --rate HZ          send rate (default 1000)\n"
    "  -d, --duration SEC     how long to run (default 10)\n"
    "  -m, --mode MODE        oneway (default), ping, or echo (reply to a ping peer)\n"
    "      --send A,B,...     signals to write each cycle (default: doubles and double\n"
    "                         arrays produced here; an array carries k in every element)\n"
    "      --recv A,B,...     signals to wait for (default: doubles consumed here); event\n"
    "                         signals named here are drained, the newest one counts\n"
    "      --warmup SEC       ignore samples in the first SEC (default 0.5)\n"
    "      --prio N           SCHED_FIFO priority for both threads (needs CAP_SYS_NICE)\n"
    "      --rx-prio N        the receive thread's priority instead (e.g. below --prio with\n"
    "                         --spin, so a spinning receiver never starves the sender)\n"
    "      --spin             receive by busy-polling the signals instead of ccomm_wait()\n"
    "                         (an RT loop's view: no wake-up; costs one core)\n"
    "      --cpu N            pin the receive thread to CPU N\n"
    "      --label TEXT       name in the JSON result\n"
    "      --samples FILE     write every latency sample (ns) to FILE\n"
    "      --stages FILE      oneway: write each sample as 'total<TAB>last hop' (ns), the last hop\n"
    "                         being the time since ccommd stored the newest value of the cycle\n"
    "                         on this node (so total - last hop = producer write -> ccommd here)\n"
    "Prints one JSON line: {label,mode,node,rate_hz,send_signals,recv_signals,sent,received,lost,min_ns,\n"
    "p50_ns,p90_ns,p99_ns,p999_ns,max_ns,mean_ns,count,overruns,first_k,last_k}; overruns: cycles the sender\n"
    "skipped because it woke a period late or more (a stalled machine), never written.\n";

struct Options {
  const char* node = nullptr;
  double rate = 1000, duration = 10, warmup = 0.5;
  std::string mode = "oneway", label = "ccomm", samples_file, stages_file;
  std::string send, recv;
  int prio = 0, rx_prio = -1;
  bool spin = false;
  int cpu = -1;
};

uint64_t Now() { return static_cast<uint64_t>(ccomm_now()); }

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size()) {
    size_t c = s.find(',', start);
    std::string p = s.substr(start, c == std::string::npos ? std::string::npos : c - start);
    if (!p.empty()) out.push_back(p);
    if (c == std::string::npos) break;
    start = c + 1;
  }
  return out;
}

constexpr size_t kHistory = 1 << 16;  // send times by cycle, for ping mode

struct Shared {
  ccomm_client* rx_client = nullptr;
  ccomm_client* tx_client = nullptr;
  std::vector<ccomm_signal> send, recv;
  std::vector<uint32_t> send_count, recv_count;  // elements (double arrays: > 1)
  std::vector<double> tx_buf, rx_buf;            // one array's elements
  std::vector<uint64_t> send_time;  // [k % kHistory]
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> sent{0};
  bool ping = false, echo = false, spin = false, stages = false;
  int cpu = -1, prio = 0;
  uint64_t warmup_until = 0;
  std::vector<int64_t> samples, last_hop;
  uint64_t first_k = 0, last_k = 0, received = 0;
  bool any = false;
  // The receiving side's measured window (as a peer's sink counts it: from the first value
  // to the end), for the CPU account: every complete value, warm-up included.
  uint64_t rx_values = 0, rx_first_ns = 0, rx_first_cpu_ns = 0, rx_last_ns = 0;
};

// One clock reading per cycle, as a control loop takes it (ccomm_set_time): every value
// of the cycle is stamped with the cycle's start, so its latency includes the writes.
void WriteAll(Shared* s, double k) {
  ccomm_set_time(s->tx_client, static_cast<int64_t>(Now()));
  for (size_t i = 0; i < s->send.size(); ++i) {
    if (s->send_count[i] == 1) {
      ccomm_write_double(s->tx_client, s->send[i], k);
    } else {  // an array: every element carries k
      std::fill(s->tx_buf.begin(), s->tx_buf.begin() + s->send_count[i], k);
      ccomm_write(s->tx_client, s->send[i], s->tx_buf.data(), s->send_count[i] * sizeof(double));
    }
  }
  ccomm_flush(s->tx_client);
}

// Reads signal i of --recv: a double, or an array of doubles whose first element is
// returned (the store hands over whole arrays, so every element is the same k).
int ReadValue(Shared* s, size_t i, double* v, ccomm_info* info) {
  if (s->recv_count[i] == 1) return ccomm_read_double(s->rx_client, s->recv[i], v, info);
  const int r = ccomm_read(s->rx_client, s->recv[i], s->rx_buf.data(), s->recv_count[i] * sizeof(double), info);
  *v = s->rx_buf[0];
  return r;
}

void* Receiver(void* arg) {
  Shared* s = static_cast<Shared*>(arg);
  const size_t n = s->recv.size();
  std::vector<uint64_t> last_seq(n, 0);
  std::vector<double> got(n, -1);
  std::vector<uint64_t> src(n, 0);
  std::vector<uint64_t> stored(n, 0);  // when ccommd stored the value here (estimate)
  double last_complete = -1;
  std::vector<bool> is_event(n, false);
  for (size_t i = 0; i < n; ++i) {
    ccomm_signal_desc d;
    is_event[i] = ccomm_describe(s->rx_client, s->recv[i], &d) == 0 && d.is_event;
    // Only values written after we started count: a value left in the segment by an
    // earlier run (its k restarted from 1 since) would otherwise block completion.
    double v;
    ccomm_info info;
    int r;
    while ((r = ReadValue(s, i, &v, &info)) == CCOMM_FRESH || r == CCOMM_STALE) {
      last_seq[i] = info.seq;
      if (!is_event[i]) break;
    }
  }
  ccomm::platform::RealtimeRequest want;
  want.cpu = s->cpu;
  want.fifo_priority = s->prio;  // best effort, reported by main
  const int err = ccomm::platform::SetUpRealtime(want).cpu;  // before the loop: a message is fine here
  if (err != 0) fprintf(stderr, "ccomm-latency: cannot pin the receive thread to CPU %d (%s)\n", s->cpu, strerror(-err));
  while (!s->stop.load(std::memory_order_relaxed)) {
    if (!s->spin) ccomm_wait(s->rx_client, 50);
    bool changed = false;
    // One clock reading per cycle (ccomm_set_time), as the docs advise control loops:
    // ages are measured from it, so the store time (t_read - age) is exact for values
    // stored before it and reads as t_read for one stored during the reads (age 0).
    const uint64_t t_read = Now();
    ccomm_set_time(s->rx_client, static_cast<int64_t>(t_read));
    for (size_t i = 0; i < n; ++i) {
      double v;
      ccomm_info info;
      int r = ReadValue(s, i, &v, &info);
      // Events queue: take every one waiting, keep the newest (one wake-up may find
      // several, and leaving them queued would delay every later sample).
      while ((r == CCOMM_FRESH || r == CCOMM_STALE) && info.seq != last_seq[i]) {
        last_seq[i] = info.seq;
        got[i] = v;
        src[i] = info.source_time_ns;
        stored[i] = t_read - static_cast<uint64_t>(info.age_ns);
        changed = true;
        if (!is_event[i]) break;
        r = ReadValue(s, i, &v, &info);
      }
    }
    if (!changed || n == 0) continue;
    const uint64_t now = Now();  // after the reads: every value seen was written before it
    double k = got[0];
    bool complete = k > last_complete;
    uint64_t latest_src = 0;
    uint64_t newest_store = 0;
    for (size_t i = 0; i < n && complete; ++i) {
      complete = got[i] == k;
      latest_src = std::max(latest_src, src[i]);
      newest_store = std::max(newest_store, stored[i]);
    }
    if (!complete) continue;
    last_complete = k;
    if (!s->rx_values++) {  // one system call, at the first value only
      s->rx_first_ns = now;
      s->rx_first_cpu_ns = ccomm::platform::ProcessCpuNs();
    }
    s->rx_last_ns = now;
    uint64_t kk = static_cast<uint64_t>(k);
    if (s->echo) {
      WriteAll(s, k);
      continue;
    }
    if (now < s->warmup_until) continue;
    int64_t lat;
    if (s->ping) {
      uint64_t t0 = s->send_time[kk % kHistory];
      if (!t0) continue;
      lat = static_cast<int64_t>(now - t0) / 2;
    } else {
      lat = static_cast<int64_t>(now - latest_src);
    }
    if (!s->any) s->first_k = kk;
    s->any = true;
    s->last_k = kk;
    s->received++;
    if (s->samples.size() < s->samples.capacity()) {
      s->samples.push_back(lat);
      s->last_hop.push_back(static_cast<int64_t>(now - newest_store));
    }
  }
  return nullptr;
}

std::vector<ccomm_signal> Resolve(ccomm_client* c, const std::string& list, bool produced, const char* what) {
  std::vector<ccomm_signal> out;
  if (!list.empty()) {
    for (const std::string& name : Split(list)) {
      ccomm_signal id = ccomm_find(c, name.c_str());
      if (id < 0) {
        fprintf(stderr, "ccomm-latency: no signal '%s' (%s)\n", name.c_str(), what);
        exit(2);
      }
      out.push_back(id);
    }
    return out;
  }
  for (int i = 0; i < ccomm_signal_count(c); ++i) {
    ccomm_signal_desc d;
    ccomm_describe(c, i, &d);
    if (d.type != CCOMM_DOUBLE || d.is_event) continue;
    if (produced ? d.produced_here : d.consumed_here) out.push_back(i);
  }
  return out;
}

// An option's number, the whole word (atof read "abc" as 0 and "5abc" as 5); false if not.
// Signed (--prio, --cpu): the checks of each option's range follow.
bool Number(const char* word, double* out) {
  char* end = nullptr;
  double v = strtod(word, &end);
  if (end == word || *end || !(v == v) || v > 1e15 || v < -1e15) return false;
  *out = v;
  return true;
}

}  // namespace


int main(int argc, char** argv) {
  Options o;
  static const struct option kLong[] = {
      {"node", required_argument, nullptr, 'n'},   {"rate", required_argument, nullptr, 'r'},
      {"duration", required_argument, nullptr, 'd'}, {"mode", required_argument, nullptr, 'm'},
      {"send", required_argument, nullptr, 'S'},   {"recv", required_argument, nullptr, 'R'},
      {"warmup", required_argument, nullptr, 'W'}, {"prio", required_argument, nullptr, 'P'},
      {"rx-prio", required_argument, nullptr, 'Q'},
      {"label", required_argument, nullptr, 'L'},  {"samples", required_argument, nullptr, 'F'},
      {"stages", required_argument, nullptr, 'G'},
      {"spin", no_argument, nullptr, 'X'},         {"cpu", required_argument, nullptr, 'C'},
      {"help", no_argument, nullptr, 'h'},         {nullptr, 0, nullptr, 0}};
  int ch;
  while ((ch = getopt_long(argc, argv, "n:r:d:m:h", kLong, nullptr)) != -1) {
    double v = 0;
    if (strchr("rdWPQC", ch) != nullptr && !Number(optarg, &v)) {
      fprintf(stderr, "ccomm-latency: '%s' is not a number\n", optarg);
      return 2;
    }
    switch (ch) {
      case 'n': o.node = optarg; break;
      case 'r': o.rate = v; break;
      case 'd': o.duration = v; break;
      case 'm': o.mode = optarg; break;
      case 'S': o.send = optarg; break;
      case 'R': o.recv = optarg; break;
      case 'W': o.warmup = v; break;
      case 'P': o.prio = static_cast<int>(v); break;
      case 'Q': o.rx_prio = static_cast<int>(v); break;
      case 'L': o.label = optarg; break;
      case 'F': o.samples_file = optarg; break;
      case 'G': o.stages_file = optarg; break;
      case 'X': o.spin = true; break;
      case 'C':
        if (v < 0 || v > 1023 || v != static_cast<int>(v)) {
          fprintf(stderr, "ccomm-latency: --cpu %s: expected a CPU number 0..1023\n", optarg);
          return 2;
        }
        o.cpu = static_cast<int>(v);
        break;
      case 'h': fputs(kUsage, stdout); return 0;
      default: fputs(kUsage, stderr); return 2;
    }
  }
  if (o.rate <= 0 || o.duration <= 0 || (o.mode != "oneway" && o.mode != "ping" && o.mode != "echo")) {
    fputs(kUsage, stderr);
    return 2;
  }
  if (o.rate * o.duration > 1e8) {  // the samples are preallocated: 16 bytes a cycle
    fprintf(stderr, "ccomm-latency: at most 1e8 cycles (rate x duration) per run\n");
    return 2;
  }
  // The output files are opened now: a run is not wasted on a file that cannot be written.
  FILE* samples_out = nullptr;
  FILE* stages_out = nullptr;
  for (auto [name, file] : {std::make_pair(&o.samples_file, &samples_out), std::make_pair(&o.stages_file, &stages_out)}) {
    if (!name->empty() && (*file = fopen(name->c_str(), "w")) == nullptr) {
      fprintf(stderr, "ccomm-latency: cannot write %s: %s\n", name->c_str(), strerror(errno));
      return 1;
    }
  }
  Shared s;
  int r = ccomm_open(o.node, CCOMM_OPEN_BATCH, &s.tx_client);
  if (r == 0) r = ccomm_open(o.node, 0, &s.rx_client);
  if (r != 0) {
    fprintf(stderr, "ccomm-latency: cannot attach: %s\n", ccomm_strerror(r));
    return 1;
  }
  s.send = Resolve(s.tx_client, o.send, true, "--send");
  s.recv = Resolve(s.rx_client, o.recv, false, "--recv");
  for (int pass = 0; pass < 2; ++pass) {
    ccomm_client* c = pass ? s.rx_client : s.tx_client;
    const std::vector<ccomm_signal>& ids = pass ? s.recv : s.send;
    std::vector<uint32_t>& counts = pass ? s.recv_count : s.send_count;
    for (ccomm_signal id : ids) {
      ccomm_signal_desc d = {};
      if (ccomm_describe(c, id, &d) != 0 || d.type != CCOMM_DOUBLE) {
        fprintf(stderr, "ccomm-latency: signal '%s' is not a double or double array\n", d.name ? d.name : "?");
        return 2;
      }
      counts.push_back(d.count);
      std::vector<double>& buf = pass ? s.rx_buf : s.tx_buf;
      if (buf.size() < d.count) buf.resize(d.count);
    }
  }
  s.ping = o.mode == "ping";
  s.echo = o.mode == "echo";
  s.spin = o.spin;
  s.cpu = o.cpu;
  s.prio = o.rx_prio >= 0 ? o.rx_prio : o.prio;
  s.stages = !o.stages_file.empty();
  s.send_time.assign(kHistory, 0);
  s.samples.reserve(static_cast<size_t>(o.rate * o.duration) + 16);
  s.last_hop.reserve(s.samples.capacity());
  ccomm::platform::RealtimeRequest lock;
  lock.lock_memory = true;
  ccomm::platform::SetUpRealtime(lock);  // best effort

  uint64_t start = Now();
  s.warmup_until = start + static_cast<uint64_t>(o.warmup * 1e9);
  pthread_t rx;
  // Only the threads the mode needs, as an application would have them: a side that only
  // sends has no receive thread (an idle ccomm_wait would be woken by each of its own
  // writes), a side that only receives or echoes no periodic loop (next below).
  const bool receives = !s.recv.empty() || s.ping || s.echo;
  const bool sends = !s.send.empty() && !s.echo;
  if (receives) pthread_create(&rx, nullptr, Receiver, &s);
  ccomm::platform::RealtimeRequest fifo;
  fifo.fifo_priority = o.prio;
  if (ccomm::platform::SetUpRealtime(fifo).fifo_priority != 0)
    fprintf(stderr, "ccomm-latency: SCHED_FIFO refused; running SCHED_OTHER\n");
  const uint64_t period = static_cast<uint64_t>(1e9 / o.rate);
  const uint64_t end = start + static_cast<uint64_t>(o.duration * 1e9);
  uint64_t next = Now();  // after the set-up above: a slow start must not fire the first cycles back to back
  uint64_t overruns = 0;  // cycles skipped because the loop woke a whole period late or more
  // The sending side's measured window (as a peer's source counts it): the send loop.
  const uint64_t tx_start_ns = Now(), tx_start_cpu_ns = ccomm::platform::ProcessCpuNs();
  while (!sends && Now() < end) ccomm::platform::SleepUntilNs(static_cast<int64_t>(end));
  for (uint64_t k = 1; sends; ++k) {
    next += period;
    ccomm::platform::SleepUntilNs(static_cast<int64_t>(next));
    const uint64_t woke = Now();
    if (woke >= end) break;
    // Woken after the next cycle's start (the machine stalled this thread): skip the
    // missed cycles, as a control loop does, instead of writing them back to back, where
    // ccommd would rightly coalesce them and the peer count them as cycles not seen.
    if (woke - next >= period) {
      const uint64_t missed = (woke - next) / period;
      overruns += missed;
      next += missed * period;
    }
    if (s.echo) continue;  // echo only answers, from the receive thread
    s.send_time[k % kHistory] = Now();
    WriteAll(&s, static_cast<double>(k));
    s.sent.fetch_add(1, std::memory_order_relaxed);
  }
  const uint64_t tx_end_ns = Now(), tx_end_cpu_ns = ccomm::platform::ProcessCpuNs();
  // Let the last frames arrive.
  ccomm::platform::SleepNsInterruptible(200 * 1000 * 1000);
  s.stop = true;
  if (receives) pthread_join(rx, nullptr);
  // This process's CPU over its measured window, every thread (docs/performance.md, "CPU
  // per value"): the send loop where it sends, else from its first value received to its
  // last (its CPU to the end: the idle wait after the last value is in it); start-up,
  // attach and memory locking are outside it, as they are for the peers.
  uint64_t win_start = 0, win_end = 0, win_cpu = 0, win_values = 0;
  if (sends) {
    win_start = tx_start_ns, win_end = tx_end_ns, win_cpu = tx_end_cpu_ns - tx_start_cpu_ns;
    win_values = s.sent.load();
  } else if (s.rx_values) {
    win_start = s.rx_first_ns, win_end = s.rx_last_ns, win_cpu = ccomm::platform::ProcessCpuNs() - s.rx_first_cpu_ns;
    win_values = s.rx_values;
  }

  std::vector<int64_t> v = s.samples;
  std::sort(v.begin(), v.end());
  auto pct = [&](double p) -> int64_t {
    if (v.empty()) return -1;
    size_t i = static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
    return v[std::min(i, v.size() - 1)];
  };
  double mean = 0;
  for (int64_t x : v) mean += static_cast<double>(x);
  if (!v.empty()) mean /= static_cast<double>(v.size());
  uint64_t expected = s.any ? s.last_k - s.first_k + 1 : 0;
  uint64_t lost = expected > s.received ? expected - s.received : 0;
  if (samples_out != nullptr) {
    for (int64_t x : s.samples) fprintf(samples_out, "%" PRId64 "\n", x);
    fclose(samples_out);
  }
  if (stages_out != nullptr) {
    for (size_t i = 0; i < s.samples.size(); ++i)
      fprintf(stages_out, "%" PRId64 "\t%" PRId64 "\n", s.samples[i], s.last_hop[i]);
    fclose(stages_out);
  }
  printf("{\"label\":\"%s\",\"mode\":\"%s\",\"node\":\"%s\",\"rate_hz\":%.0f,\"send_signals\":%zu,"
         "\"recv_signals\":%zu,\"sent\":%" PRIu64 ",\"received\":%" PRIu64 ",\"lost\":%" PRIu64
         ",\"min_ns\":%" PRId64 ",\"p50_ns\":%" PRId64 ",\"p90_ns\":%" PRId64 ",\"p99_ns\":%" PRId64
         ",\"p999_ns\":%" PRId64 ",\"max_ns\":%" PRId64 ",\"mean_ns\":%.0f,\"count\":%zu,"
         "\"overruns\":%" PRIu64 ",\"first_k\":%" PRIu64 ",\"last_k\":%" PRIu64 ",\"window_start_ns\":%" PRIu64
         ",\"window_end_ns\":%" PRIu64 ",\"window_cpu_ns\":%" PRIu64 ",\"window_values\":%" PRIu64 "}\n",
         ccomm::app::JsonText(o.label.c_str()).c_str(), o.mode.c_str(), ccomm_node_name(s.rx_client), o.rate, s.send.size(), s.recv.size(),
         s.sent.load(), s.received, lost, pct(0), pct(0.5), pct(0.9), pct(0.99), pct(0.999),
         v.empty() ? -1 : v.back(), mean, v.size(), overruns, s.first_k, s.last_k, win_start, win_end, win_cpu,
         win_values);
  ccomm_close(s.tx_client);
  ccomm_close(s.rx_client);
  return 0;
}
