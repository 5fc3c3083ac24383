// SPDX-License-Identifier: Apache-2.0
// One loaded FMU binary (dlopen) and its co-simulation instance, FMI 2.0 or 3.0 behind one
// interface. Start-up calls (Load, Instantiate, Initialize) allocate; Get, Set and DoStep are
// what the FMU does plus one indirect call.
#ifndef CCOMM_FMU_FMU_BINARY_H
#define CCOMM_FMU_FMU_BINARY_H
#include <string>

#include "fmi_abi.h"
#include "model_description.h"

namespace ccomm::fmu {

// The FMI call running now (for the crash message); written before each call into the FMU.
extern const char* volatile g_current_call;

// The platform directory of binaries/ for this build ("x86_64-linux" / "linux64"...).
const char* PlatformDirectory(int fmi_major);

class FmuBinary {
 public:
  ~FmuBinary();
  // dlopen of <dir>/binaries/<platform>/<modelIdentifier>.so and every symbol needed.
  bool Load(const std::string& dir, const ModelDescription& md, std::string* error);
  bool Instantiate(const std::string& instance_name, bool logging_on, std::string* error);
  // Initialization mode with start time 0, no stop time.
  bool Initialize(std::string* error);
  // `values` holds `count` elements in ccomm's layout (bool = 1 byte). 0 or an FMI status.
  int Get(FmiType type, uint32_t vr, uint32_t count, void* values);
  int Set(FmiType type, uint32_t vr, uint32_t count, const void* values);
  // 0 (OK/Warning), else the status; *terminate set when the FMU asks to stop.
  int DoStep(double t, double h, bool* terminate);
  // Leaves the instance as the last status allows (Terminate unless Error/Fatal) and frees it.
  void Finish(int last_status);
  int fmi_major() const { return major_; }

 private:
  void* Symbol(const char* name, std::string* error);
  int major_ = 0;
  void* lib_ = nullptr;
  void* instance_ = nullptr;
  std::string dir_, token_, identifier_;
  // FMI 3.0
  Fmi3InstantiateCoSimulation instantiate3_ = nullptr;
  Fmi3FreeInstance free3_ = nullptr;
  Fmi3EnterInitializationMode enter_init3_ = nullptr;
  Fmi3Simple exit_init3_ = nullptr, terminate3_ = nullptr;
  Fmi3DoStep do_step3_ = nullptr;
  Fmi3GetValues get3_[6] = {};
  Fmi3SetValues set3_[6] = {};
  // FMI 2.0
  Fmi2Instantiate instantiate2_ = nullptr;
  Fmi2FreeInstance free2_ = nullptr;
  Fmi2SetupExperiment setup2_ = nullptr;
  Fmi2Simple enter_init2_ = nullptr, exit_init2_ = nullptr, terminate2_ = nullptr;
  Fmi2DoStep do_step2_ = nullptr;
  Fmi2GetValues get2_real_ = nullptr, get2_int_ = nullptr, get2_bool_ = nullptr;
  Fmi2SetValues set2_real_ = nullptr, set2_int_ = nullptr, set2_bool_ = nullptr;
  Fmi2GetBooleanStatus get2_bool_status_ = nullptr;
  Fmi2CallbackFunctions callbacks2_{};
};

const char* StatusName(int status);

}  // namespace ccomm::fmu
#endif
