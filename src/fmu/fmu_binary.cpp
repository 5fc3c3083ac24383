// SPDX-License-Identifier: Apache-2.0
#include "fmu_binary.h"

#include <dlfcn.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace ccomm::fmu {

const char* volatile g_current_call = "(start-up)";

const char* PlatformDirectory(int fmi_major) {
#if defined(__x86_64__)
  return fmi_major == 3 ? "x86_64-linux" : "linux64";
#elif defined(__aarch64__)
  return fmi_major == 3 ? "aarch64-linux" : "linux64";
#elif defined(__arm__)
  return fmi_major == 3 ? "aarch32-linux" : "linux32";  // FMI 2.0 has no ARM name: built here
#elif defined(__i386__)
  return fmi_major == 3 ? "x86-linux" : "linux32";
#else
#error "unknown platform: add its FMI platform tuple"
#endif
}

const char* StatusName(int status) {
  static const char* const kNames[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
  return status >= 0 && status <= 5 ? kNames[status] : "(unknown status)";
}

namespace {
// The FMU's log messages go to stderr: the journal under systemd.
void Log3(Fmi3InstanceEnvironment, int status, const char* category, const char* message) {
  std::fprintf(stderr, "ccomm-fmu: FMU %s [%s]: %s\n", StatusName(status), category ? category : "",
               message ? message : "");
}
void Log2(void*, const char* instance, int status, const char* category, const char* message, ...) {
  std::fprintf(stderr, "ccomm-fmu: FMU %s %s [%s]: ", instance ? instance : "", StatusName(status),
               category ? category : "");
  va_list ap;
  va_start(ap, message);
  std::vfprintf(stderr, message ? message : "", ap);
  va_end(ap);
  std::fputc('\n', stderr);
}
void* Calloc(size_t n, size_t size) { return std::calloc(n, size); }
void Free(void* p) { std::free(p); }
const char* const kFmi3TypeNames[6] = {"Float64", "Float32", "Int32", "UInt32", "Int64", "Boolean"};
}  // namespace

FmuBinary::~FmuBinary() {
  if (lib_ != nullptr) dlclose(lib_);
}

void* FmuBinary::Symbol(const char* name, std::string* error) {
  void* p = dlsym(lib_, name);
  if (p == nullptr && error->empty()) *error = std::string("the FMU binary does not export ") + name;
  return p;
}

bool FmuBinary::Load(const std::string& dir, const ModelDescription& md, std::string* error) {
  major_ = md.fmi_major;
  dir_ = dir;
  token_ = md.token;
  identifier_ = md.model_identifier;
  std::string so = dir + "/binaries/" + PlatformDirectory(major_) + "/" + md.model_identifier + ".so";
  lib_ = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib_ == nullptr) {
    std::string why = dlerror();
    if (why.rfind(so + ": ", 0) == 0) why.erase(0, so.size() + 2);  // dlerror names the file again
    *error = so + ": cannot load: " + why + " (no binary for this platform? a source FMU: ccomm-fmu build)";
    return false;
  }
  error->clear();
  if (major_ == 3) {
    instantiate3_ = reinterpret_cast<Fmi3InstantiateCoSimulation>(Symbol("fmi3InstantiateCoSimulation", error));
    free3_ = reinterpret_cast<Fmi3FreeInstance>(Symbol("fmi3FreeInstance", error));
    enter_init3_ = reinterpret_cast<Fmi3EnterInitializationMode>(Symbol("fmi3EnterInitializationMode", error));
    exit_init3_ = reinterpret_cast<Fmi3Simple>(Symbol("fmi3ExitInitializationMode", error));
    terminate3_ = reinterpret_cast<Fmi3Simple>(Symbol("fmi3Terminate", error));
    do_step3_ = reinterpret_cast<Fmi3DoStep>(Symbol("fmi3DoStep", error));
    for (int i = 0; i < 6; ++i) {
      std::string get = std::string("fmi3Get") + kFmi3TypeNames[i], set = std::string("fmi3Set") + kFmi3TypeNames[i];
      get3_[i] = reinterpret_cast<Fmi3GetValues>(Symbol(get.c_str(), error));
      set3_[i] = reinterpret_cast<Fmi3SetValues>(Symbol(set.c_str(), error));
    }
  } else {
    instantiate2_ = reinterpret_cast<Fmi2Instantiate>(Symbol("fmi2Instantiate", error));
    free2_ = reinterpret_cast<Fmi2FreeInstance>(Symbol("fmi2FreeInstance", error));
    setup2_ = reinterpret_cast<Fmi2SetupExperiment>(Symbol("fmi2SetupExperiment", error));
    enter_init2_ = reinterpret_cast<Fmi2Simple>(Symbol("fmi2EnterInitializationMode", error));
    exit_init2_ = reinterpret_cast<Fmi2Simple>(Symbol("fmi2ExitInitializationMode", error));
    terminate2_ = reinterpret_cast<Fmi2Simple>(Symbol("fmi2Terminate", error));
    do_step2_ = reinterpret_cast<Fmi2DoStep>(Symbol("fmi2DoStep", error));
    get2_real_ = reinterpret_cast<Fmi2GetValues>(Symbol("fmi2GetReal", error));
    get2_int_ = reinterpret_cast<Fmi2GetValues>(Symbol("fmi2GetInteger", error));
    get2_bool_ = reinterpret_cast<Fmi2GetValues>(Symbol("fmi2GetBoolean", error));
    set2_real_ = reinterpret_cast<Fmi2SetValues>(Symbol("fmi2SetReal", error));
    set2_int_ = reinterpret_cast<Fmi2SetValues>(Symbol("fmi2SetInteger", error));
    set2_bool_ = reinterpret_cast<Fmi2SetValues>(Symbol("fmi2SetBoolean", error));
    get2_bool_status_ = reinterpret_cast<Fmi2GetBooleanStatus>(Symbol("fmi2GetBooleanStatus", error));
  }
  if (!error->empty()) {
    *error = so + ": " + *error;
    return false;
  }
  return true;
}

bool FmuBinary::Instantiate(const std::string& instance_name, bool logging_on, std::string* error) {
  std::string resources = dir_ + "/resources/";
  g_current_call = major_ == 3 ? "fmi3InstantiateCoSimulation" : "fmi2Instantiate";
  if (major_ == 3) {
    instance_ = instantiate3_(instance_name.c_str(), token_.c_str(), resources.c_str(), false, logging_on,
                              false, false, nullptr, 0, nullptr, Log3, nullptr);
  } else {
    callbacks2_ = Fmi2CallbackFunctions{Log2, Calloc, Free, nullptr, nullptr};
    std::string uri = "file://" + resources;
    instance_ = instantiate2_(instance_name.c_str(), kFmi2CoSimulation, token_.c_str(), uri.c_str(), &callbacks2_,
                              0, logging_on ? 1 : 0);
  }
  if (instance_ == nullptr) {
    *error = std::string(g_current_call) + " failed (see the FMU's messages above)";
    return false;
  }
  return true;
}

bool FmuBinary::Initialize(std::string* error) {
  int s;
  if (major_ == 3) {
    g_current_call = "fmi3EnterInitializationMode";
    s = enter_init3_(instance_, false, 0.0, 0.0, false, 0.0);
    if (s <= kFmi3Warning) {
      g_current_call = "fmi3ExitInitializationMode";
      s = exit_init3_(instance_);
    }
  } else {
    g_current_call = "fmi2SetupExperiment";
    s = setup2_(instance_, 0, 0.0, 0.0, 0, 0.0);
    if (s <= kFmi2Warning) {
      g_current_call = "fmi2EnterInitializationMode";
      s = enter_init2_(instance_);
    }
    if (s <= kFmi2Warning) {
      g_current_call = "fmi2ExitInitializationMode";
      s = exit_init2_(instance_);
    }
  }
  if (s > 1) {
    *error = std::string(g_current_call) + " returned " + StatusName(s);
    return false;
  }
  return true;
}

int FmuBinary::Get(FmiType type, uint32_t vr, uint32_t count, void* values) {
  if (major_ == 3) {
    int s = get3_[static_cast<int>(type)](instance_, &vr, 1, values, count);
    return s <= kFmi3Warning ? 0 : s;
  }
  int s;
  if (type == FmiType::kFloat64) {
    s = get2_real_(instance_, &vr, 1, values);
  } else if (type == FmiType::kInt32) {
    s = get2_int_(instance_, &vr, 1, values);
  } else {  // fmi2Boolean is an int; ccomm's bool is one byte
    int b = 0;
    s = get2_bool_(instance_, &vr, 1, &b);
    *static_cast<uint8_t*>(values) = b != 0;
  }
  return s <= kFmi2Warning ? 0 : s;
}

int FmuBinary::Set(FmiType type, uint32_t vr, uint32_t count, const void* values) {
  if (major_ == 3) {
    int s = set3_[static_cast<int>(type)](instance_, &vr, 1, values, count);
    return s <= kFmi3Warning ? 0 : s;
  }
  int s;
  if (type == FmiType::kFloat64) {
    s = set2_real_(instance_, &vr, 1, values);
  } else if (type == FmiType::kInt32) {
    s = set2_int_(instance_, &vr, 1, values);
  } else {
    int b = *static_cast<const uint8_t*>(values) != 0;
    s = set2_bool_(instance_, &vr, 1, &b);
  }
  return s <= kFmi2Warning ? 0 : s;
}

int FmuBinary::DoStep(double t, double h, bool* terminate) {
  int s;
  *terminate = false;
  if (major_ == 3) {
    g_current_call = "fmi3DoStep";
    bool event = false, early = false;
    double last = 0;
    s = do_step3_(instance_, t, h, true, &event, terminate, &early, &last);
  } else {
    g_current_call = "fmi2DoStep";
    s = do_step2_(instance_, t, h, 1);
    if (s == kFmi2Discard) {
      int terminated = 0;
      if (get2_bool_status_(instance_, kFmi2Terminated, &terminated) <= kFmi2Warning) *terminate = terminated != 0;
    }
  }
  g_current_call = "(between FMI calls)";
  return s <= 1 ? 0 : s;
}

void FmuBinary::Finish(int last_status) {
  if (instance_ == nullptr || last_status >= kFmi3Fatal) return;  // Fatal: the instance is gone
  if (last_status < kFmi3Error) {
    g_current_call = major_ == 3 ? "fmi3Terminate" : "fmi2Terminate";
    major_ == 3 ? terminate3_(instance_) : terminate2_(instance_);
  }
  g_current_call = major_ == 3 ? "fmi3FreeInstance" : "fmi2FreeInstance";
  major_ == 3 ? free3_(instance_) : free2_(instance_);
  instance_ = nullptr;
}

}  // namespace ccomm::fmu
