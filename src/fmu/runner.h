// SPDX-License-Identifier: Apache-2.0
// The real-time part of ccomm-fmu: FMU variables bound to ccomm signals, and the periodic
// task that reads, steps and writes them.
#ifndef CCOMM_FMU_RUNNER_H
#define CCOMM_FMU_RUNNER_H
#include <signal.h>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ccomm/ccomm.h"
#include "fmu_binary.h"
#include "mapping.h"
#include "model_description.h"

namespace ccomm::fmu {

struct RunOptions {
  const char* node = nullptr;
  int64_t period_ns = 0;
  uint64_t cycles = 0;  // 0 = until stopped
  std::string record_path;
  bool realtime = true;
  int priority = 80;
  int cpu = -1;
  bool fmu_logging = false;
  bool measure = false;
};

// The FMU's files: the directory given, or a .fmu unzipped into a private temporary
// directory that is removed again: at exit, and also when the process ends by _exit (a
// hung or crashed FMU), SIGKILL or anything else, by a small watcher process that removes
// it once this one is gone.
class UnpackedFmu {
 public:
  ~UnpackedFmu();
  bool Open(const std::string& path, std::string* error);
  const std::string& dir() const { return dir_; }
  // How a message names the FMU's file `member` ("binaries/x86_64-linux/m.so"): the FMU's
  // own path and the member, never the temporary copy, which is gone when it is read.
  std::string Shown(const std::string& member) const;
  // `text` (dlerror's, xmllint's) with the temporary directory named as Shown() does.
  std::string Unpacked(std::string text) const;

 private:
  std::string dir_, path_;
  bool temporary_ = false;
  int watcher_fd_ = -1;  // the watcher removes dir_ when this closes (our exit)
};

// `ccomm-fmu build FMU [--cc CC] [--out FILE]` (build.cpp).
int BuildSourceFmu(const std::string& fmu_path, int argc, char** argv);

class Runner {
 public:
  Runner(const ModelDescription& md, FmuBinary& binary, const RunOptions& opt)
      : md_(md), binary_(binary), opt_(opt) {}
  ~Runner();
  // Attaches to the node and binds every input, output and tunable parameter to its signal.
  bool Bind(const std::vector<MappingLine>& mapping, const std::string& map_path, std::string* error);
  void PrintBindings(FILE* out) const;
  // Instantiates the FMU and runs the task until *stop, --cycles, or a failure; exit status.
  int Run(volatile sig_atomic_t* stop);
  const char* node_name() const { return ccomm_node_name(client_); }
  volatile uint64_t* cycle_counter() { return &cycle_; }

 private:
  enum class Kind { kInput, kFreshness, kOutput, kParameter };
  struct Binding {
    const Variable* var;
    ccomm_signal signal;
    std::string signal_name;
    Kind kind;
    uint32_t bytes;
    std::vector<uint8_t> value;     // what the FMU was given / gave (the record shows it)
    std::vector<uint8_t> incoming;  // what ccomm_read returned this cycle
    uint64_t last_seq = 0;
  };
  void SetUpRealtime();
  int Fail(int status, const char* what);
  int Retired();  // ccommd replaced the segment: exit status 75
  void Report(FILE* out) const;
  void WriteRecord() const;
  // One record cell: a double's bits, or an integer (Int64 kept exact: 2^53 + 1 is not a
  // double), as RecordIsInteger() tells for its column.
  static uint64_t RecordCell(const Binding& b, uint32_t i);
  static bool RecordIsInteger(const Binding& b);

  const ModelDescription& md_;
  FmuBinary& binary_;
  RunOptions opt_;
  ccomm_client* client_ = nullptr;
  std::vector<Binding> bindings_;
  uint32_t record_columns_ = 0;
  std::unique_ptr<uint64_t[]> record_;  // --cycles rows, preallocated (cells: RecordCell)
  std::vector<bool> record_integer_;     // per column: an integer cell, else a double's bits
  FILE* record_file_ = nullptr;  // --record, opened before the first cycle
  volatile uint64_t cycle_ = 0;
  // Statistics (nanoseconds).
  uint64_t overruns_ = 0, read_errors_ = 0, write_errors_ = 0, stale_reads_ = 0, never_reads_ = 0;
  int64_t max_lateness_ = 0, sum_lateness_ = 0;
  int64_t max_step_ = 0, sum_step_ = 0, max_cycle_ = 0, sum_cycle_ = 0;
};

}  // namespace ccomm::fmu
#endif
