// SPDX-License-Identifier: Apache-2.0
// The FMI 2.0 and 3.0 co-simulation calls ccomm-fmu makes, as function types of the binary
// interface the standard fixes (fmi2FunctionTypes.h, fmi3FunctionTypes.h). Declared here
// so the product builds without the standard's headers (no Debian package ships them).
// Getters and setters share one pointer type (values as void*: the same calling convention).
// tests/fmu runs FMUs compiled against the standard's headers (FMPy's copy) through these.
#ifndef CCOMM_FMU_FMI_ABI_H
#define CCOMM_FMU_FMI_ABI_H
#include <stddef.h>
#include <stdint.h>

extern "C" {
// ---- FMI 3.0 ----
typedef void* Fmi3Instance;
typedef void* Fmi3InstanceEnvironment;
typedef uint32_t Fmi3ValueReference;
enum Fmi3Status : int { kFmi3OK = 0, kFmi3Warning, kFmi3Discard, kFmi3Error, kFmi3Fatal };
typedef void (*Fmi3LogMessageCallback)(Fmi3InstanceEnvironment, int status, const char* category,
                                       const char* message);
typedef void (*Fmi3IntermediateUpdateCallback)(Fmi3InstanceEnvironment, double time, bool set_requested,
                                               bool get_allowed, bool step_finished, bool can_return_early,
                                               bool* early_return_requested, double* early_return_time);
typedef const char* (*Fmi3GetVersion)(void);
typedef Fmi3Instance (*Fmi3InstantiateCoSimulation)(const char* instance_name, const char* token,
                                                    const char* resource_path, bool visible, bool logging_on,
                                                    bool event_mode_used, bool early_return_allowed,
                                                    const Fmi3ValueReference* required_intermediate,
                                                    size_t n_required_intermediate, Fmi3InstanceEnvironment env,
                                                    Fmi3LogMessageCallback log,
                                                    Fmi3IntermediateUpdateCallback intermediate_update);
typedef void (*Fmi3FreeInstance)(Fmi3Instance);
typedef int (*Fmi3EnterInitializationMode)(Fmi3Instance, bool tolerance_defined, double tolerance,
                                           double start_time, bool stop_time_defined, double stop_time);
typedef int (*Fmi3Simple)(Fmi3Instance);  // ExitInitializationMode, Terminate
typedef int (*Fmi3DoStep)(Fmi3Instance, double current_point, double step_size, bool no_set_state_prior,
                          bool* event_handling_needed, bool* terminate_simulation, bool* early_return,
                          double* last_successful_time);
// Getters and setters of the six value types ccomm has (one pattern: vr[], nvr, values[], n).
typedef int (*Fmi3GetValues)(Fmi3Instance, const Fmi3ValueReference*, size_t, void*, size_t);
typedef int (*Fmi3SetValues)(Fmi3Instance, const Fmi3ValueReference*, size_t, const void*, size_t);

// ---- FMI 2.0 ----
typedef void* Fmi2Component;
typedef unsigned int Fmi2ValueReference;
enum Fmi2Status : int { kFmi2OK = 0, kFmi2Warning, kFmi2Discard, kFmi2Error, kFmi2Fatal, kFmi2Pending };
enum { kFmi2CoSimulation = 1, kFmi2Terminated = 3 };
struct Fmi2CallbackFunctions {
  void (*logger)(void* env, const char* instance_name, int status, const char* category, const char* message, ...);
  void* (*allocate_memory)(size_t, size_t);
  void (*free_memory)(void*);
  void (*step_finished)(void* env, int status);
  void* component_environment;
};
typedef const char* (*Fmi2GetVersion)(void);
typedef Fmi2Component (*Fmi2Instantiate)(const char* instance_name, int type, const char* guid,
                                         const char* resource_location, const Fmi2CallbackFunctions*,
                                         int visible, int logging_on);
typedef void (*Fmi2FreeInstance)(Fmi2Component);
typedef int (*Fmi2SetupExperiment)(Fmi2Component, int tolerance_defined, double tolerance, double start_time,
                                   int stop_time_defined, double stop_time);
typedef int (*Fmi2Simple)(Fmi2Component);  // Enter/ExitInitializationMode, Terminate
typedef int (*Fmi2DoStep)(Fmi2Component, double current_point, double step_size, int no_set_state_prior);
typedef int (*Fmi2GetValues)(Fmi2Component, const Fmi2ValueReference*, size_t, void*);
typedef int (*Fmi2SetValues)(Fmi2Component, const Fmi2ValueReference*, size_t, const void*);
typedef int (*Fmi2GetBooleanStatus)(Fmi2Component, int kind, int* value);
}
#endif
