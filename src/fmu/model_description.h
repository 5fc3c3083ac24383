// SPDX-License-Identifier: Apache-2.0
// modelDescription.xml of an FMI 2.0 or 3.0 co-simulation FMU: what ccomm-fmu needs of it,
// with a structural check (every error names file:line). The XSD check is separate
// (xmllint against the standard's schemas, when given: docs/integrations/fmi.md).
#ifndef CCOMM_FMU_MODEL_DESCRIPTION_H
#define CCOMM_FMU_MODEL_DESCRIPTION_H
#include <cstdint>
#include <string>
#include <vector>

namespace ccomm::fmu {

// FMI value types ccomm has a signal type for; kOther is refused when mapped.
enum class FmiType { kFloat64, kFloat32, kInt32, kUInt32, kInt64, kBool, kOther };
enum class Causality { kInput, kOutput, kParameter, kOther };

struct Variable {
  std::string name;
  uint32_t value_reference = 0;
  FmiType type = FmiType::kOther;
  std::string type_name;   // as written: Float64, Real, Int8...
  Causality causality = Causality::kOther;
  std::string variability; // continuous, discrete, fixed, tunable, constant
  uint32_t count = 1;      // FMI 3.0 arrays: product of the dimensions
  int line = 0;
};

struct ModelDescription {
  int fmi_major = 0;  // 2 or 3
  std::string model_name, token, model_identifier;
  double default_step = 0;  // DefaultExperiment stepSize, 0 if absent
  double fixed_internal_step = 0;  // FMI 3.0 fixedInternalStepSize hint, 0 if absent
  bool needs_execution_tool = false;
  std::vector<Variable> variables;
  std::vector<std::string> source_files;  // FMI 2.0 CoSimulation/SourceFiles
  const Variable* Find(const std::string& name) const;
};

// Parses `path`; false with a file:line message in `error`.
bool LoadModelDescription(const std::string& path, ModelDescription* out, std::string* error);
// The same on `text` already read (`path` names it in messages).
bool ParseModelDescription(const std::string& path, const std::string& text, ModelDescription* out,
                           std::string* error);

// FMI 3.0 sources/buildDescription.xml: the C sources of `model_identifier` and how to
// compile them (paths relative to sources/).
struct BuildDescription {
  std::vector<std::string> sources, defines /* NAME or NAME=VALUE */, include_dirs;
};
bool LoadBuildDescription(const std::string& path, const std::string& model_identifier, BuildDescription* out,
                          std::string* error);

// Reads a whole file; false if it cannot.
bool ReadFile(const std::string& path, std::string* out, std::string* error);  // error: "PATH: cannot read: why"

}  // namespace ccomm::fmu
#endif
