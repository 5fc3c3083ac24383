// SPDX-License-Identifier: Apache-2.0
#include "runner.h"

#include <fcntl.h>
#include <ftw.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdlib>
#include <cstring>
#include <map>
#include <new>

#include "common/public/platform_app.h"

extern char** environ;

namespace ccomm::fmu {
namespace {

int CcommTypeOf(FmiType t) {
  switch (t) {
    case FmiType::kFloat64: return CCOMM_DOUBLE;
    case FmiType::kFloat32: return CCOMM_FLOAT;
    case FmiType::kInt32: return CCOMM_INT32;
    case FmiType::kUInt32: return CCOMM_UINT32;
    case FmiType::kInt64: return CCOMM_INT64;
    case FmiType::kBool: return CCOMM_BOOL;
    default: return 0;
  }
}
const char* CcommTypeName(int t) {
  const char* name = ccomm_type_name(static_cast<int32_t>(t));
  return name ? name : "?";
}
int64_t Now() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1000000000LL + ts.tv_nsec;
}
int RemoveEntry(const char* path, const struct stat*, int, FTW*) { return remove(path); }

}  // namespace

UnpackedFmu::~UnpackedFmu() {
  if (temporary_) nftw(dir_.c_str(), RemoveEntry, 16, FTW_DEPTH | FTW_PHYS);
  if (watcher_fd_ >= 0) close(watcher_fd_);
}

std::string UnpackedFmu::Shown(const std::string& member) const {
  return temporary_ ? path_ + ": " + member : dir_ + "/" + member;
}

std::string UnpackedFmu::Unpacked(std::string text) const {
  if (!temporary_) return text;
  const std::string prefix = dir_ + "/";
  for (size_t at; (at = text.find(prefix)) != std::string::npos;) text.replace(at, prefix.size(), path_ + ": ");
  return text;
}

namespace {
// The watcher: forked before anything else runs (one thread, nothing locked), it holds
// no descriptor but the pipe's read end, ignores the stop signals (systemd's SIGTERM goes
// to the whole unit) and waits for end of file: the FMU task has ended, however it did.
// Then it removes the copy. It costs the task nothing while it runs (a sleeping process).
int StartWatcher(const std::string& dir) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return -1;
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return -1;
  }
  if (pid == 0) {
    for (int s : {SIGTERM, SIGINT, SIGHUP, SIGALRM}) signal(s, SIG_IGN);
    dup2(fds[0], 0);
    close_range(1, ~0U, 0);
    const int null = open("/dev/null", O_RDWR);  // fds 1 and 2: a log pipe is not held open
    if (null >= 0) {
      dup2(null, 1);
      dup2(null, 2);
    }
    setsid();  // not the task's process group: a kill of the task's group leaves it
    char c;
    while (read(0, &c, 1) != 0 && errno == EINTR) {
    }
    nftw(dir.c_str(), RemoveEntry, 16, FTW_DEPTH | FTW_PHYS);
    _exit(0);
  }
  close(fds[0]);
  return fds[1];
}
}  // namespace

bool UnpackedFmu::Open(const std::string& path, std::string* error) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0) {
    *error = path + ": " + std::strerror(errno);
    return false;
  }
  if (S_ISDIR(st.st_mode)) {
    char* real = realpath(path.c_str(), nullptr);
    dir_ = real != nullptr ? real : path;
    std::free(real);
    return true;
  }
  const char* tmp = std::getenv("TMPDIR");
  std::string templ = std::string(tmp != nullptr && *tmp ? tmp : "/tmp") + "/ccomm-fmu-XXXXXX";
  if (mkdtemp(&templ[0]) == nullptr) {
    *error = "cannot create a directory to unpack " + path + ": " + std::strerror(errno);
    return false;
  }
  dir_ = templ;
  path_ = path;
  temporary_ = true;
  watcher_fd_ = StartWatcher(dir_);
  // An FMU is a zip archive: unzip (busybox has one) keeps this program free of an archive library.
  const char* argv[] = {"unzip", "-q", "-o", path.c_str(), "-d", dir_.c_str(), nullptr};
  pid_t pid;
  int status = 0;
  if (posix_spawnp(&pid, "unzip", nullptr, nullptr, const_cast<char**>(argv), environ) != 0 ||
      waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    *error = "cannot unpack " + path + " (unzip failed or is missing): is it an FMU?";
    return false;
  }
  return true;
}

Runner::~Runner() {
  if (client_ != nullptr) ccomm_close(client_);
}

bool Runner::Bind(const std::vector<MappingLine>& mapping, const std::string& map_path, std::string* error) {
  int rc = ccomm_open(opt_.node, CCOMM_OPEN_BATCH, &client_);
  if (rc != 0) {
    const char* env = std::getenv("CCOMM_NODE");
    const std::string node = opt_.node     ? std::string(opt_.node)
                             : env && *env ? std::string(env) + " (from $CCOMM_NODE)"
                                           : std::string("of this host name (no --node, no $CCOMM_NODE)");
    *error = "cannot attach to node " + node + ": " + ccomm_strerror(rc);
    return false;
  }
  std::map<std::string, const MappingLine*> by_variable;
  for (const MappingLine& m : mapping) {
    const Variable* v = md_.Find(m.variable);
    auto at = [&](const std::string& msg) {
      *error = map_path + ":" + std::to_string(m.line) + ": " + msg;
      return false;
    };
    if (v == nullptr) return at("the FMU has no variable \"" + m.variable + "\"");
    if (m.freshness && (v->causality != Causality::kInput || v->type != FmiType::kBool || v->count != 1))
      return at("fresh(" + m.signal + ") needs a scalar Boolean input; \"" + m.variable + "\" is not one");
    if (!m.signal.empty() && v->causality == Causality::kParameter && v->variability != "tunable")
      return at("parameter \"" + m.variable + "\" is " + v->variability +
                ", not tunable: it cannot follow a signal while running");
    if (!m.signal.empty() && v->causality == Causality::kOther)
      return at("\"" + m.variable + "\" is neither an input, an output nor a parameter");
    by_variable[m.variable] = &m;
  }
  for (const Variable& v : md_.variables) {
    if (v.causality == Causality::kOther) continue;
    auto it = by_variable.find(v.name);
    const MappingLine* m = it != by_variable.end() ? it->second : nullptr;
    if (m != nullptr && m->signal.empty()) continue;  // "= -": not connected
    const bool tunable = v.causality == Causality::kParameter && v.variability == "tunable";
    if (v.causality == Causality::kParameter && !tunable) continue;
    const std::string where = "modelDescription.xml:" + std::to_string(v.line) + ": ";
    const char* role = v.causality == Causality::kInput ? "input" : v.causality == Causality::kOutput ? "output"
                                                                                                       : "parameter";
    Binding b{&v, -1, m != nullptr ? m->signal : v.name, Kind::kInput, 0, {}, {}, 0};
    b.kind = m != nullptr && m->freshness ? Kind::kFreshness
             : v.causality == Causality::kInput ? Kind::kInput
             : v.causality == Causality::kOutput ? Kind::kOutput : Kind::kParameter;
    b.signal = ccomm_find(client_, b.signal_name.c_str());
    if (b.signal < 0) {
      if (tunable && m == nullptr) continue;  // parameters follow a signal only where one exists
      *error = where + std::string("FMU ") + role + " \"" + v.name + "\": no signal \"" + b.signal_name +
               "\" on node " + ccomm_node_name(client_) + " (map it to another signal or to - in a --map file)";
      return false;
    }
    ccomm_signal_desc d;
    ccomm_describe(client_, b.signal, &d);
    if (d.is_event) {
      *error = where + "signal \"" + b.signal_name + "\" is an event; ccomm-fmu maps state signals only";
      return false;
    }
    if (b.kind == Kind::kFreshness) {
      b.bytes = d.value_bytes;
    } else {
      if (v.type == FmiType::kOther) {
        *error = where + std::string("FMU ") + role + " \"" + v.name + "\" has type " + v.type_name +
                 ", which ccomm has no signal type for (supported: Float64/Real, Float32, Int32/Integer, UInt32, "
                 "Int64, Boolean); map it to - to leave it unconnected";
        return false;
      }
      if (d.type != CcommTypeOf(v.type) || d.count != v.count) {
        *error = where + std::string("type mismatch: FMU ") + role + " \"" + v.name + "\" is " + v.type_name +
                 (v.count > 1 ? "[" + std::to_string(v.count) + "]" : "") + ", signal \"" + b.signal_name + "\" is " +
                 CcommTypeName(d.type) + (d.count > 1 ? "[" + std::to_string(d.count) + "]" : "") +
                 " (needs " + CcommTypeName(CcommTypeOf(v.type)) +
                 (v.count > 1 ? "[" + std::to_string(v.count) + "]" : "") + ")";
        return false;
      }
      b.bytes = d.value_bytes;
    }
    if (b.kind == Kind::kOutput && !d.produced_here) {
      *error = where + "FMU output \"" + v.name + "\" -> signal \"" + b.signal_name + "\": node " +
               ccomm_node_name(client_) + " is not its producer (" + d.producer + " is)";
      return false;
    }
    if (b.kind != Kind::kOutput && !d.produced_here && !d.consumed_here) {
      *error = where + "signal \"" + b.signal_name + "\" does not reach node " + ccomm_node_name(client_) +
               " (add it to the signal's consumers)";
      return false;
    }
    b.value.assign(b.bytes, 0);
    b.incoming.assign(b.bytes, 0);
    bindings_.push_back(std::move(b));
  }
  for (const Binding& b : bindings_) record_columns_ += b.kind == Kind::kFreshness ? 1 : b.var->count;
  return true;
}

void Runner::PrintBindings(FILE* out) const {
  for (const Binding& b : bindings_) {
    const char* arrow = b.kind == Kind::kOutput ? "->" : "<-";
    std::fprintf(out, "ccomm-fmu: %-9s %s %s %s%s%s\n",
                 b.kind == Kind::kInput ? "input" : b.kind == Kind::kFreshness ? "freshness"
                 : b.kind == Kind::kOutput ? "output" : "parameter",
                 b.var->name.c_str(), arrow, b.kind == Kind::kFreshness ? "fresh(" : "", b.signal_name.c_str(),
                 b.kind == Kind::kFreshness ? ")" : "");
  }
}

void Runner::SetUpRealtime() {
  ccomm::platform::RealtimeRequest want;
  want.cpu = opt_.cpu;  // also with --no-rt: --cpu is an option of its own
  if (opt_.realtime) {
    want.lock_memory = true;
    want.fifo_priority = opt_.priority;
  }
  const ccomm::platform::RealtimeResult got = ccomm::platform::SetUpRealtime(want);
  if (got.cpu != 0)
    std::fprintf(stderr, "ccomm-fmu: warning: cannot pin to CPU %d (%s)\n", opt_.cpu, std::strerror(-got.cpu));
  if (!opt_.realtime) return;
  if (got.lock_memory != 0)
    std::fprintf(stderr, "ccomm-fmu: warning: mlockall failed (%s): page faults may delay cycles\n",
                 std::strerror(-got.lock_memory));
  if (got.fifo_priority != 0)
    std::fprintf(stderr, "ccomm-fmu: warning: SCHED_FIFO %d not permitted (%s): running SCHED_OTHER, "
                 "without real-time guarantees (give CAP_SYS_NICE or an rtprio limit)\n",
                 opt_.priority, std::strerror(-got.fifo_priority));
  // Touch the stack the FMU may use so that its pages are resident before the first cycle.
  volatile char stack[256 * 1024];
  for (size_t i = 0; i < sizeof stack; i += 4096) stack[i] = 0;
}

int Runner::Fail(int status, const char* what) {
  std::fprintf(stderr, "ccomm-fmu: the FMU %s %s at t = %.9g s (cycle %" PRIu64 "); the task stops, its outputs "
               "turn stale for their consumers\n", md_.model_name.c_str(), what,
               static_cast<double>(cycle_) * opt_.period_ns * 1e-9, static_cast<uint64_t>(cycle_));
  binary_.Finish(status);
  Report(stderr);
  WriteRecord();
  return 3;
}

int Runner::Retired() {
  std::fputs("ccomm-fmu: ccommd replaced the segment (new configuration): stopping; restart the task\n", stderr);
  binary_.Finish(kFmi3OK);
  WriteRecord();
  return 75;
}

uint64_t Runner::RecordCell(const Binding& b, uint32_t i) {
  const uint8_t* p = b.value.data();
  auto bits = [](double v) { uint64_t u; std::memcpy(&u, &v, 8); return u; };
  if (b.kind == Kind::kFreshness) return p[0];
  switch (b.var->type) {
    case FmiType::kFloat64: { double v; std::memcpy(&v, p + 8 * i, 8); return bits(v); }
    case FmiType::kFloat32: { float v; std::memcpy(&v, p + 4 * i, 4); return bits(v); }
    case FmiType::kInt32: { int32_t v; std::memcpy(&v, p + 4 * i, 4); return static_cast<uint64_t>(int64_t{v}); }
    case FmiType::kUInt32: { uint32_t v; std::memcpy(&v, p + 4 * i, 4); return v; }
    case FmiType::kInt64: { int64_t v; std::memcpy(&v, p + 8 * i, 8); return static_cast<uint64_t>(v); }
    default: return p[i];
  }
}

bool Runner::RecordIsInteger(const Binding& b) {
  return b.kind == Kind::kFreshness || (b.var->type != FmiType::kFloat64 && b.var->type != FmiType::kFloat32);
}

int Runner::Run(volatile sig_atomic_t* stop) {
  std::string error;
  const uint32_t columns = 3 + record_columns_ + (opt_.measure ? 2 : 0);
  if (!opt_.record_path.empty()) {  // preallocated before the loop; refused here rather than lost at exit
    record_file_ = std::fopen(opt_.record_path.c_str(), "w");
    if (record_file_ == nullptr) {
      std::fprintf(stderr, "ccomm-fmu: --record %s: %s\n", opt_.record_path.c_str(), std::strerror(errno));
      return 1;
    }
    if (opt_.cycles <= SIZE_MAX / sizeof(double) / columns)
      record_.reset(new (std::nothrow) uint64_t[opt_.cycles * columns]());
    record_integer_ = {true, false, true};  // cycle, time, lateness_ns
    for (const Binding& b : bindings_)
      record_integer_.insert(record_integer_.end(), b.kind == Kind::kFreshness ? 1 : b.var->count,
                             RecordIsInteger(b));
    if (opt_.measure) record_integer_.insert(record_integer_.end(), {true, true});
    if (!record_) {
      std::fprintf(stderr, "ccomm-fmu: --record: cannot hold %" PRIu64 " cycles of %u values in memory: give fewer "
                   "--cycles\n", static_cast<uint64_t>(opt_.cycles), columns);
      return 1;
    }
  }
  if (!binary_.Instantiate(md_.model_name, opt_.fmu_logging, &error) || !binary_.Initialize(&error)) {
    std::fprintf(stderr, "ccomm-fmu: %s: %s\n", md_.model_name.c_str(), error.c_str());
    binary_.Finish(kFmi3Error);
    return 1;
  }
  // The values the FMU holds before the first cycle (start values), so that the record
  // shows what each cycle really gave the FMU also before a signal's first value.
  for (Binding& b : bindings_)
    if (b.kind == Kind::kInput || b.kind == Kind::kParameter)
      binary_.Get(b.var->type, b.var->value_reference, b.var->count, b.value.data());
  SetUpRealtime();
  std::fprintf(stderr, "ccomm-fmu: running %s (FMI %d.0) every %g ms on node %s\n", md_.model_name.c_str(),
               binary_.fmi_major(), opt_.period_ns * 1e-6, ccomm_node_name(client_));
  const int64_t period = opt_.period_ns;
  // Model time t_k = k * h exactly (no drift over long runs); each doStep spans t_k..t_k+1.
  const double h = static_cast<double>(period) / 1e9;
  int64_t release = Now();
  while (!*stop && (opt_.cycles == 0 || cycle_ < opt_.cycles)) {
    const int64_t now = Now();  // the cycle's one clock reading
    int64_t late = now - release;
    if (late >= period) {  // missed releases: counted, skipped; the model advances one period per cycle
      const int64_t missed = late / period;
      overruns_ += static_cast<uint64_t>(missed);
      release += missed * period;
      late -= missed * period;
    }
    if (late > max_lateness_) max_lateness_ = late;
    sum_lateness_ += late;
    ccomm_set_time(client_, now);
    const double t = static_cast<double>(cycle_) * h;
    for (Binding& b : bindings_) {
      if (b.kind == Kind::kOutput) continue;
      ccomm_info info;
      int rc = ccomm_read(client_, b.signal, b.incoming.data(), b.bytes, &info);
      if (rc == CCOMM_E_RETIRED) return Retired();
      if (rc < 0) { ++read_errors_; continue; }
      if (rc == CCOMM_STALE) ++stale_reads_;
      if (rc == CCOMM_NEVER) ++never_reads_;
      int set = 0;
      if (b.kind == Kind::kFreshness) {
        uint8_t fresh = rc == CCOMM_FRESH;
        b.value[0] = fresh;
        set = binary_.Set(FmiType::kBool, b.var->value_reference, 1, &fresh);
      } else if (rc == CCOMM_NEVER && !(info.flags & CCOMM_INFO_SAFE_VALUE)) {
        continue;  // nothing yet and no safe value: the FMU keeps its start value
      } else {
        if (b.kind == Kind::kParameter) {
          if (info.seq == b.last_seq && !(info.flags & CCOMM_INFO_SAFE_VALUE)) continue;  // set new values only
          b.last_seq = info.seq;
        }
        std::memcpy(b.value.data(), b.incoming.data(), b.bytes);
        set = binary_.Set(b.var->type, b.var->value_reference, b.var->count, b.value.data());
      }
      if (set != 0) return Fail(set, (std::string("refused input ") + b.var->name + " (" + StatusName(set) + ")").c_str());
    }
    bool terminate = false;
    const int64_t step_start = opt_.measure ? Now() : 0;
    const int s = binary_.DoStep(t, static_cast<double>(cycle_ + 1) * h - t, &terminate);
    const int64_t step_end = opt_.measure ? Now() : 0;
    if (s != 0) return Fail(s, (std::string("returned ") + StatusName(s) + " from doStep").c_str());
    if (terminate) return Fail(kFmi3OK, "asked to terminate the simulation in doStep");
    for (Binding& b : bindings_) {
      if (b.kind != Kind::kOutput) continue;
      int g = binary_.Get(b.var->type, b.var->value_reference, b.var->count, b.value.data());
      if (g != 0) return Fail(g, (std::string("refused to give output ") + b.var->name).c_str());
      const int w = ccomm_write(client_, b.signal, b.value.data(), b.bytes);
      if (w == CCOMM_E_RETIRED) return Retired();  // an FMU with outputs only learns it here
      if (w != 0) ++write_errors_;
    }
    const int f = ccomm_flush(client_);  // the outputs leave in one frame
    if (f == CCOMM_E_RETIRED) return Retired();
    if (f != 0) ++write_errors_;
    if (opt_.measure) {
      const int64_t end = Now();
      max_step_ = std::max(max_step_, step_end - step_start);
      sum_step_ += step_end - step_start;
      max_cycle_ = std::max(max_cycle_, end - now);
      sum_cycle_ += end - now;
    }
    if (record_) {
      uint64_t* row = &record_[cycle_ * columns];
      *row++ = cycle_;
      std::memcpy(row++, &t, 8);
      *row++ = static_cast<uint64_t>(late);
      for (const Binding& b : bindings_) {
        const uint32_t n = b.kind == Kind::kFreshness ? 1 : b.var->count;
        for (uint32_t i = 0; i < n; ++i) *row++ = RecordCell(b, i);
      }
      if (opt_.measure) {
        *row++ = static_cast<uint64_t>(step_end - step_start);
        *row++ = static_cast<uint64_t>(Now() - now);
      }
    }
    cycle_ = cycle_ + 1;
    release += period;
    while (ccomm::platform::SleepUntilNs(release) == -EINTR && !*stop) {
    }
  }
  binary_.Finish(kFmi3OK);
  Report(stderr);
  WriteRecord();
  return 0;
}

void Runner::Report(FILE* out) const {
  const uint64_t n = cycle_ > 0 ? cycle_ : 1;
  std::fprintf(out, "ccomm-fmu: %" PRIu64 " cycles, %" PRIu64 " overruns (missed releases; the model lags real "
               "time by as many periods), lateness mean %.1f us max %.1f us, %" PRIu64 " stale reads, %" PRIu64
               " reads of signals that never had a value, %" PRIu64 " read errors, %" PRIu64 " write errors\n",
               static_cast<uint64_t>(cycle_), overruns_, sum_lateness_ / 1e3 / n, max_lateness_ / 1e3, stale_reads_,
               never_reads_, read_errors_, write_errors_);
  if (opt_.measure)
    std::fprintf(out, "ccomm-fmu: doStep mean %.2f us max %.2f us; whole cycle mean %.2f us max %.2f us; "
                 "ccomm-fmu's own cost per cycle %.2f us\n", sum_step_ / 1e3 / n, max_step_ / 1e3,
                 sum_cycle_ / 1e3 / n, max_cycle_ / 1e3, (sum_cycle_ - sum_step_) / 1e3 / n);
}

void Runner::WriteRecord() const {
  FILE* f = record_file_;  // opened at start
  if (f == nullptr) return;
  std::fputs("cycle,time,lateness_ns", f);
  for (const Binding& b : bindings_) {
    const uint32_t n = b.kind == Kind::kFreshness ? 1 : b.var->count;
    for (uint32_t i = 0; i < n; ++i)
      n > 1 ? std::fprintf(f, ",%s[%u]", b.var->name.c_str(), i) : std::fprintf(f, ",%s", b.var->name.c_str());
  }
  if (opt_.measure) std::fputs(",dostep_ns,cycle_ns", f);
  std::fputc('\n', f);
  const uint32_t columns = 3 + record_columns_ + (opt_.measure ? 2 : 0);
  for (uint64_t r = 0; r < cycle_; ++r) {
    for (uint32_t c = 0; c < columns; ++c) {
      const uint64_t cell = record_[r * columns + c];
      if (c != 0) std::fputc(',', f);
      if (record_integer_[c]) {
        std::fprintf(f, "%" PRId64, static_cast<int64_t>(cell));
      } else {
        double v;
        std::memcpy(&v, &cell, 8);
        std::fprintf(f, "%.17g", v);
      }
    }
    std::fputc('\n', f);
  }
  std::fclose(f);
}

}  // namespace ccomm::fmu
