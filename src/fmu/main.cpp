// SPDX-License-Identifier: Apache-2.0
// ccomm-fmu: runs one FMI 2.0 / 3.0 co-simulation FMU as a periodic real-time task whose
// inputs, outputs and tunable parameters are ccomm signals (docs/integrations/fmi.md).
// One process per FMU: a crash inside the FMU ends this process only; its outputs then
// turn stale for their consumers and ccommd and other clients go on.
#include <getopt.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "ccomm/ccomm.h"
#include "fmu_binary.h"
#include "mapping.h"
#include "model_description.h"
#include "hang_watch.h"
#include "runner.h"

namespace ccomm::fmu {
namespace {

const char kUsage[] =
    "Usage: ccomm-fmu run FMU [OPTIONS]     run FMU (a .fmu file or an unpacked directory)\n"
    "       ccomm-fmu check FMU [OPTIONS]   validate it and its mapping against the signals, then exit\n"
    "       ccomm-fmu build FMU [--cc CC] [--fmi-include DIR] [--out FILE]   compile a source FMU\n"
    "  -n, --node NAME        node to attach to (default $CCOMM_NODE / hostname)\n"
    "  -p, --period TIME      task period (1ms, 500us, 0.002s); default the FMU's DefaultExperiment\n"
    "                         stepSize. Each cycle advances the model by exactly one period.\n"
    "      --ignore-default-step  run at --period although the FMU's stepSize differs\n"
    "  -m, --map FILE         mapping file (default: every variable maps to the signal of its name)\n"
    "      --cycles N         stop after N cycles (default: run until SIGTERM/SIGINT)\n"
    "      --record FILE      write every cycle's inputs and outputs as CSV at exit (needs --cycles)\n"
    "      --priority N       SCHED_FIFO priority (default 80); --no-rt: stay SCHED_OTHER\n"
    "      --cpu N            pin the task to CPU N\n"
    "      --schema-dir DIR   also validate modelDescription.xml against DIR/fmi3 or fmi2 XSDs (xmllint)\n"
    "      --fmu-log          turn on the FMU's debug logging (messages go to stderr / the journal)\n"
    "      --measure          time each doStep and each whole cycle (two more clock readings per cycle)\n"
    "      --hang-timeout TIME  a doStep running this long has hung: say so, exit 3 (default the\n"
    "                         larger of 1 s and 100 periods; 0 turns the watch off)\n"
    "Exit status: 0 stopped by a signal or after --cycles; 1 refused at start; 3 the FMU failed;\n"
    "70 the FMU crashed; 75 ccommd replaced the segment (restart).\n";

volatile sig_atomic_t g_stop = 0;
void OnStop(int) { g_stop = 1; }

// Crash inside the FMU (or anywhere): one async-signal-safe message, then _exit. The
// outputs are not written again, so they turn stale for consumers.
char g_crash_name[128] = "";
volatile uint64_t* g_cycle_for_crash = nullptr;
void Put(const char* s) { (void)!write(2, s, std::strlen(s)); }
void OnCrash(int sig) {
  const char* name = sig == SIGSEGV ? "SIGSEGV" : sig == SIGBUS ? "SIGBUS" : sig == SIGFPE ? "SIGFPE"
                   : sig == SIGILL ? "SIGILL" : "SIGABRT";
  char num[24];
  uint64_t c = g_cycle_for_crash != nullptr ? *g_cycle_for_crash : 0;
  int i = sizeof num - 1;
  num[i] = '\0';
  do { num[--i] = static_cast<char>('0' + c % 10); c /= 10; } while (c != 0 && i > 0);
  Put("ccomm-fmu: the FMU ");
  Put(g_crash_name);
  Put(" crashed (");
  Put(name);
  Put(") in ");
  Put(g_current_call);
  Put(" at cycle ");
  Put(num + i);
  Put("; the task stops, its outputs turn stale for their consumers\n");
  _exit(70);
}

void InstallHandlers() {
  static char alt_stack[64 * 1024];
  stack_t ss{};
  ss.ss_sp = alt_stack;
  ss.ss_size = sizeof alt_stack;
  sigaltstack(&ss, nullptr);
  struct sigaction sa {};
  sa.sa_handler = OnCrash;
  sa.sa_flags = SA_ONSTACK | SA_RESETHAND;
  for (int s : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) sigaction(s, &sa, nullptr);
  struct sigaction st {};
  st.sa_handler = OnStop;
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaction(s, &st, nullptr);
}

// The period (--period or the FMU's stepSize): 1 us to 1 h, so that it fits the cycle arithmetic.
constexpr double kMinPeriodNs = 1e3, kMaxPeriodNs = 3600e9;

bool ParsePeriod(const char* s, int64_t* ns) {
  char* end = nullptr;
  double v = std::strtod(s, &end);
  double scale = 0;
  if (std::strcmp(end, "ms") == 0) scale = 1e6;
  else if (std::strcmp(end, "us") == 0) scale = 1e3;
  else if (std::strcmp(end, "s") == 0) scale = 1e9;
  else if (std::strcmp(end, "ns") == 0) scale = 1;
  if (scale == 0 || !(v * scale >= kMinPeriodNs && v * scale <= kMaxPeriodNs)) return false;
  *ns = std::llround(v * scale);
  return true;
}

// A whole decimal number in [min, max] for --cycles, --priority, --cpu: no silent 0 for "abc".
bool ParseCount(const char* option, const char* s, uint64_t min, uint64_t max, uint64_t* out) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s, &end, 10);
  if (*s < '0' || *s > '9' || *end != '\0' || errno != 0 || v < min || v > max) {
    std::fprintf(stderr, "ccomm-fmu: %s %s: expected a whole number from %llu to %llu\n", option, s,
                 static_cast<unsigned long long>(min), static_cast<unsigned long long>(max));
    return false;
  }
  *out = v;
  return true;
}

// Runs xmllint against the standard's schema (FMPy ships them); false with its output.
bool ValidateSchema(const std::string& schema_dir, int major, const std::string& xml, std::string* error) {
  std::string xsd = schema_dir + (major == 3 ? "/fmi3/fmi3ModelDescription.xsd" : "/fmi2/fmi2ModelDescription.xsd");
  if (access(xsd.c_str(), R_OK) != 0) {
    *error = xsd + ": cannot read the schema";
    return false;
  }
  if (xsd.find('\'') != std::string::npos || xml.find('\'') != std::string::npos) {
    *error = "a path with a quote cannot be handed to xmllint";
    return false;
  }
  std::string cmd = "xmllint --noout --schema '" + xsd + "' '" + xml + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) {
    *error = "cannot run xmllint";
    return false;
  }
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  int rc = pclose(p);
  if (rc != 0) {
    *error = "modelDescription.xml does not validate against " + xsd + ":\n" + out;
    return false;
  }
  return true;
}

int Main(int argc, char** argv) {
  // --help or -h anywhere (also "run --help") asks for the usage, not for an FMU of that name.
  bool help = false;
  for (int i = 1; i < argc; ++i) help = help || std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0;
  if (help || argc < 3 || (std::strcmp(argv[1], "run") != 0 && std::strcmp(argv[1], "check") != 0 &&
                           std::strcmp(argv[1], "build") != 0)) {
    std::fputs(kUsage, help ? stdout : stderr);
    return help ? 0 : 1;
  }
  const std::string command = argv[1];
  const std::string fmu_path = argv[2];
  if (command == "build") return BuildSourceFmu(fmu_path, argc - 2, argv + 2);
  RunOptions opt;
  std::string map_path, schema_dir;
  int64_t period_ns = 0;
  bool ignore_default_step = false;
  enum { kIgnoreStep = 256, kCycles, kRecord, kPriority, kNoRt, kCpu, kSchema, kFmuLog, kMeasure, kHangTimeout };
  int64_t hang_timeout_ns = -1;  // -1: the default, from the period
  static const option kLong[] = {
      {"node", required_argument, nullptr, 'n'},          {"period", required_argument, nullptr, 'p'},
      {"map", required_argument, nullptr, 'm'},           {"ignore-default-step", no_argument, nullptr, kIgnoreStep},
      {"cycles", required_argument, nullptr, kCycles},    {"record", required_argument, nullptr, kRecord},
      {"priority", required_argument, nullptr, kPriority}, {"no-rt", no_argument, nullptr, kNoRt},
      {"cpu", required_argument, nullptr, kCpu},          {"schema-dir", required_argument, nullptr, kSchema},
      {"fmu-log", no_argument, nullptr, kFmuLog},         {"measure", no_argument, nullptr, kMeasure},
      {"hang-timeout", required_argument, nullptr, kHangTimeout},
      {nullptr, 0, nullptr, 0}};
  optind = 3;
  int ch;
  uint64_t number = 0;
  while ((ch = getopt_long(argc, argv, "n:p:m:", kLong, nullptr)) != -1) {
    switch (ch) {
      case 'n': opt.node = optarg; break;
      case 'p':
        if (!ParsePeriod(optarg, &period_ns)) {
          std::fprintf(stderr, "ccomm-fmu: --period %s: expected a time from 1us to 3600s like 1ms, 500us, 0.002s\n",
                       optarg);
          return 1;
        }
        break;
      case 'm': map_path = optarg; break;
      case kIgnoreStep: ignore_default_step = true; break;
      case kCycles:
        if (!ParseCount("--cycles", optarg, 0, UINT64_MAX, &number)) return 1;
        opt.cycles = number;
        break;
      case kRecord: opt.record_path = optarg; break;
      case kPriority:
        if (!ParseCount("--priority", optarg, 1, 99, &number)) return 1;
        opt.priority = static_cast<int>(number);
        break;
      case kNoRt: opt.realtime = false; break;
      case kCpu:
        if (!ParseCount("--cpu", optarg, 0, CPU_SETSIZE - 1, &number)) return 1;
        opt.cpu = static_cast<int>(number);
        break;
      case kSchema: schema_dir = optarg; break;
      case kFmuLog: opt.fmu_logging = true; break;
      case kMeasure: opt.measure = true; break;
      case kHangTimeout:
        if (std::strcmp(optarg, "0") == 0) {
          hang_timeout_ns = 0;
        } else if (!ParsePeriod(optarg, &hang_timeout_ns) || hang_timeout_ns < 4000000) {
          std::fprintf(stderr, "ccomm-fmu: --hang-timeout %s: expected 0 (off) or a time from 4ms to 3600s like 1s, "
                       "250ms\n", optarg);
          return 1;
        }
        break;
      default: std::fputs(kUsage, stderr); return 1;
    }
  }
  if (!opt.record_path.empty() && opt.cycles == 0) {
    std::fputs("ccomm-fmu: --record needs --cycles (the record is preallocated)\n", stderr);
    return 1;
  }
  InstallHandlers();

  UnpackedFmu unpacked;
  std::string error;
  if (!unpacked.Open(fmu_path, &error)) {
    std::fprintf(stderr, "ccomm-fmu: %s\n", error.c_str());
    return 1;
  }
  ModelDescription md;
  const std::string md_path = unpacked.dir() + "/modelDescription.xml";
  // Messages name the FMU's own file and the member in it (UnpackedFmu::Unpacked), not
  // the temporary copy, which is gone when they are read.
  if (!LoadModelDescription(md_path, &md, &error)) {
    std::fprintf(stderr, "ccomm-fmu: %s\n", unpacked.Unpacked(error).c_str());
    return 1;
  }
  if (!schema_dir.empty() && !ValidateSchema(schema_dir, md.fmi_major, md_path, &error)) {
    std::fprintf(stderr, "ccomm-fmu: %s: %s\n", fmu_path.c_str(), unpacked.Unpacked(error).c_str());
    return 1;
  }
  std::snprintf(g_crash_name, sizeof g_crash_name, "%s", md.model_name.c_str());
  if (md.needs_execution_tool) {
    std::fprintf(stderr, "ccomm-fmu: %s needs its execution tool (needsExecutionTool=\"true\"): a tool-coupling "
                 "FMU cannot run stand-alone on a board\n", fmu_path.c_str());
    return 1;
  }
  // The period and the model's step: never silently run the model at another speed.
  if (md.default_step != 0 && !(md.default_step * 1e9 >= kMinPeriodNs && md.default_step * 1e9 <= kMaxPeriodNs) &&
      !(period_ns != 0 && ignore_default_step)) {
    std::fprintf(stderr, "ccomm-fmu: the FMU's DefaultExperiment stepSize %g s is outside 1 us to 3600 s: give "
                 "--period and --ignore-default-step to run it anyway\n", md.default_step);
    return 1;
  }
  const int64_t default_step_ns =
      md.default_step * 1e9 <= kMaxPeriodNs ? std::llround(md.default_step * 1e9) : 0;
  if (period_ns == 0) {
    if (default_step_ns == 0) {
      std::fprintf(stderr, "ccomm-fmu: %s has no DefaultExperiment stepSize: give --period\n", fmu_path.c_str());
      return 1;
    }
    period_ns = default_step_ns;
  } else if (default_step_ns != 0 && default_step_ns != period_ns && !ignore_default_step) {
    std::fprintf(stderr,
                 "ccomm-fmu: the FMU's DefaultExperiment stepSize is %g s but --period is %g s. ccomm-fmu advances the "
                 "model by exactly one period per cycle (model time = real time); give --period %gs to use the FMU's "
                 "step, or --ignore-default-step to run doStep(%g s) every %g s anyway\n",
                 md.default_step, period_ns * 1e-9, md.default_step, period_ns * 1e-9, period_ns * 1e-9);
    return 1;
  }
  if (md.fixed_internal_step > 0) {
    double ratio = period_ns * 1e-9 / md.fixed_internal_step;
    if (std::fabs(ratio - std::round(ratio)) > 1e-9 || ratio < 0.5) {
      std::fprintf(stderr, "ccomm-fmu: the period %g s is not a whole multiple of the FMU's fixedInternalStepSize "
                   "%g s: refused (the FMU would have to interpolate)\n", period_ns * 1e-9, md.fixed_internal_step);
      return 1;
    }
  }
  opt.period_ns = period_ns;

  std::vector<MappingLine> mapping;
  if (!map_path.empty() && !LoadMapping(map_path, &mapping, &error)) {
    std::fprintf(stderr, "ccomm-fmu: %s\n", error.c_str());
    return 1;
  }
  FmuBinary binary;
  if (!binary.Load(unpacked.dir(), md, &error)) {
    std::fprintf(stderr, "ccomm-fmu: %s\n", unpacked.Unpacked(error).c_str());
    return 1;
  }
  Runner runner(md, binary, opt);
  if (!runner.Bind(mapping, map_path, &error)) {
    std::fprintf(stderr, "ccomm-fmu: %s: %s\n", fmu_path.c_str(), error.c_str());
    return 1;
  }
  runner.PrintBindings(stderr);
  if (command == "check") {
    // "Everything up to the first cycle": also instantiate and initialize (a licence check,
    // a missing resource or a bad instantiationToken fail here, not only in run).
    if (!binary.Instantiate(md.model_name, opt.fmu_logging, &error) || !binary.Initialize(&error)) {
      std::fprintf(stderr, "ccomm-fmu: %s: %s\n", md.model_name.c_str(), error.c_str());
      binary.Finish(kFmi3Error);
      return 1;
    }
    binary.Finish(kFmi3OK);
    std::printf("ccomm-fmu: %s (FMI %d.0, %s) maps onto node %s: ok\n", fmu_path.c_str(), md.fmi_major,
                md.model_name.c_str(), runner.node_name());
    return 0;
  }
  g_cycle_for_crash = runner.cycle_counter();
  if (hang_timeout_ns < 0) hang_timeout_ns = std::max<int64_t>(1000000000, 100 * opt.period_ns);
  if (hang_timeout_ns > 0 && !StartHangWatch(hang_timeout_ns, md.model_name.c_str(), runner.cycle_counter(), &g_stop,
                                             &error)) {
    std::fprintf(stderr, "ccomm-fmu: %s\n", error.c_str());
    return 1;
  }
  return runner.Run(&g_stop);
}

}  // namespace
}  // namespace ccomm::fmu

int main(int argc, char** argv) { return ccomm::fmu::Main(argc, argv); }
