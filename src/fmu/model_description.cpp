// SPDX-License-Identifier: Apache-2.0
#include "model_description.h"

#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>

#define RAPIDXML_NO_EXCEPTIONS
#include <rapidxml/rapidxml.hpp>

namespace {
// RapidXML without exceptions calls this and it must not return: longjmp back to Parse().
// Only trivially destructible frames (RapidXML's own) lie between, as in the config parser.
struct ParseFailure {
  std::jmp_buf env;
  const char* what = nullptr;
  const char* where = nullptr;
};
ParseFailure* g_failure = nullptr;
}  // namespace

namespace rapidxml {
void parse_error_handler(const char* what, void* where) {
  g_failure->what = what;
  g_failure->where = static_cast<const char*>(where);
  std::longjmp(g_failure->env, 1);
}
}  // namespace rapidxml

namespace ccomm::fmu {
namespace {
using Node = rapidxml::xml_node<char>;

int LineOf(const std::string& text, const char* p) {
  if (p == nullptr || p < text.data() || p > text.data() + text.size()) return 0;
  int line = 1;
  for (const char* q = text.data(); q < p; ++q) line += *q == '\n';
  return line;
}

const char* Attr(const Node* n, const char* name) {
  const rapidxml::xml_attribute<char>* a = n->first_attribute(name);
  return a != nullptr ? a->value() : nullptr;
}

bool ParseDouble(const char* s, double* out) {
  if (s == nullptr || *s == '\0') return false;
  char* end = nullptr;
  *out = std::strtod(s, &end);
  return *end == '\0';
}
bool ParseU32(const char* s, uint32_t* out) {
  if (s == nullptr || *s == '\0' || *s == '-') return false;
  char* end = nullptr;
  unsigned long long v = std::strtoull(s, &end, 10);
  if (*end != '\0' || v > 0xffffffffull) return false;
  *out = static_cast<uint32_t>(v);
  return true;
}

FmiType TypeOf(int major, const std::string& t) {
  if (major == 2) {
    if (t == "Real") return FmiType::kFloat64;
    if (t == "Integer") return FmiType::kInt32;
    if (t == "Boolean") return FmiType::kBool;
    return FmiType::kOther;
  }
  if (t == "Float64") return FmiType::kFloat64;
  if (t == "Float32") return FmiType::kFloat32;
  if (t == "Int32") return FmiType::kInt32;
  if (t == "UInt32") return FmiType::kUInt32;
  if (t == "Int64") return FmiType::kInt64;
  if (t == "Boolean") return FmiType::kBool;
  return FmiType::kOther;
}

Causality CausalityOf(const char* c) {
  if (c == nullptr) return Causality::kOther;  // FMI default "local"
  if (std::strcmp(c, "input") == 0) return Causality::kInput;
  if (std::strcmp(c, "output") == 0) return Causality::kOutput;
  if (std::strcmp(c, "parameter") == 0) return Causality::kParameter;
  return Causality::kOther;
}

class Parser {
 public:
  Parser(const std::string& path, const std::string& text) : path_(path), text_(text) {}
  bool Fail(const char* where, const std::string& message) {
    error_ = path_ + ":" + std::to_string(LineOf(text_, where)) + ": " + message;
    return false;
  }
  bool Run(Node* root, ModelDescription* md);
  const std::string& error() const { return error_; }

 private:
  bool Variables(Node* list, ModelDescription* md);
  bool Dimensions(Node* var, const ModelDescription& md, uint32_t* count);
  const std::string& path_;
  const std::string& text_;
  std::string error_;
  std::map<uint32_t, std::string> vr_start_;  // FMI 3.0: start values by value reference (dimensions)
};

bool Parser::Run(Node* root, ModelDescription* md) {
  if (root == nullptr || std::strcmp(root->name(), "fmiModelDescription") != 0)
    return Fail(root != nullptr ? root->name() : nullptr, "root element is not <fmiModelDescription>");
  const char* version = Attr(root, "fmiVersion");
  if (version == nullptr) return Fail(root->name(), "<fmiModelDescription> has no fmiVersion");
  if (std::strncmp(version, "3.", 2) == 0) {
    md->fmi_major = 3;
  } else if (std::strcmp(version, "2.0") == 0) {
    md->fmi_major = 2;
  } else {
    return Fail(version, std::string("fmiVersion \"") + version + "\" is not supported (2.0 and 3.x are)");
  }
  const char* name = Attr(root, "modelName");
  const char* token = Attr(root, md->fmi_major == 3 ? "instantiationToken" : "guid");
  if (name == nullptr) return Fail(root->name(), "<fmiModelDescription> has no modelName");
  if (token == nullptr)
    return Fail(root->name(), md->fmi_major == 3 ? "no instantiationToken" : "no guid");
  md->model_name = name;
  md->token = token;
  Node* cs = root->first_node("CoSimulation");
  if (cs == nullptr)
    return Fail(root->name(), "the FMU has no <CoSimulation> interface (model exchange and scheduled "
                              "execution are not supported)");
  const char* id = Attr(cs, "modelIdentifier");
  if (id == nullptr || *id == '\0') return Fail(cs->name(), "<CoSimulation> has no modelIdentifier");
  for (const char* p = id; *p; ++p)
    if (*p == '/' || *p == '.') return Fail(id, "modelIdentifier is not a plain file name");
  md->model_identifier = id;
  const char* net = Attr(cs, "needsExecutionTool");
  md->needs_execution_tool = net != nullptr && std::strcmp(net, "true") == 0;
  const char* fixed = Attr(cs, "fixedInternalStepSize");
  if (fixed != nullptr && (!ParseDouble(fixed, &md->fixed_internal_step) || !(md->fixed_internal_step > 0) ||
                           !std::isfinite(md->fixed_internal_step)))
    return Fail(fixed, "fixedInternalStepSize is not a positive number");
  if (md->fmi_major == 2) {
    if (Node* sf = cs->first_node("SourceFiles"))
      for (Node* f = sf->first_node("File"); f != nullptr; f = f->next_sibling("File")) {
        const char* fn = Attr(f, "name");
        if (fn == nullptr) return Fail(f->name(), "<File> has no name");
        md->source_files.push_back(fn);
      }
  }
  if (Node* de = root->first_node("DefaultExperiment")) {
    const char* step = Attr(de, "stepSize");
    if (step != nullptr && (!ParseDouble(step, &md->default_step) || !(md->default_step > 0) ||
                             !std::isfinite(md->default_step)))
      return Fail(step, "DefaultExperiment stepSize is not a positive number");
  }
  Node* list = root->first_node("ModelVariables");
  if (list == nullptr) return Fail(root->name(), "no <ModelVariables>");
  return Variables(list, md);
}

bool Parser::Dimensions(Node* var, const ModelDescription& md, uint32_t* count) {
  uint64_t product = 1;
  for (Node* d = var->first_node("Dimension"); d != nullptr; d = d->next_sibling("Dimension")) {
    uint32_t n = 0;
    const char* start = Attr(d, "start");
    const char* vr = Attr(d, "valueReference");
    if (start != nullptr) {
      if (!ParseU32(start, &n)) return Fail(start, "Dimension start is not a non-negative integer");
    } else if (vr != nullptr) {
      uint32_t ref = 0;
      auto it = ParseU32(vr, &ref) ? vr_start_.find(ref) : vr_start_.end();
      if (it == vr_start_.end() || !ParseU32(it->second.c_str(), &n))
        return Fail(vr, std::string("Dimension valueReference ") + vr +
                            " is not an earlier structural parameter with an integer start");
    } else {
      return Fail(d->name(), "<Dimension> has neither start nor valueReference");
    }
    product *= n;
    if (product > 0xffffffu) return Fail(d->name(), "array larger than 16 M elements");
  }
  (void)md;
  *count = static_cast<uint32_t>(product);
  return true;
}

bool Parser::Variables(Node* list, ModelDescription* md) {
  std::set<std::string> names;
  std::set<std::pair<std::string, uint32_t>> refs;  // FMI 2.0: unique per type; 3.0: unique
  for (Node* v = list->first_node(); v != nullptr; v = v->next_sibling()) {
    if (v->type() != rapidxml::node_element) continue;
    Variable var;
    var.line = LineOf(text_, v->name());
    Node* typed = v;
    if (md->fmi_major == 2) {
      if (std::strcmp(v->name(), "ScalarVariable") != 0)
        return Fail(v->name(), std::string("unexpected <") + v->name() + "> in <ModelVariables>");
      typed = v->first_node();
      while (typed != nullptr && typed->type() != rapidxml::node_element) typed = typed->next_sibling();
      if (typed == nullptr) return Fail(v->name(), "<ScalarVariable> without a type element");
    }
    var.type_name = typed->name();
    var.type = TypeOf(md->fmi_major, var.type_name);
    const char* name = Attr(v, "name");
    const char* vr = Attr(v, "valueReference");
    if (name == nullptr || *name == '\0') return Fail(v->name(), "variable without a name");
    var.name = name;
    if (!ParseU32(vr, &var.value_reference))
      return Fail(vr != nullptr ? vr : v->name(), "variable \"" + var.name + "\" has no valid valueReference");
    if (!names.insert(var.name).second) return Fail(name, "variable \"" + var.name + "\" defined twice");
    std::string ref_kind = md->fmi_major == 2 ? var.type_name : std::string();
    if (!refs.insert({ref_kind, var.value_reference}).second)
      return Fail(vr, "valueReference " + std::to_string(var.value_reference) + " used twice");
    const char* causality = Attr(v, "causality");
    var.causality = CausalityOf(causality);
    if (causality != nullptr && var.causality == Causality::kOther && std::strcmp(causality, "local") != 0 &&
        std::strcmp(causality, "independent") != 0 && std::strcmp(causality, "calculatedParameter") != 0 &&
        std::strcmp(causality, "structuralParameter") != 0)
      return Fail(causality, std::string("unknown causality \"") + causality + "\"");
    const char* variability = Attr(v, "variability");
    var.variability = variability != nullptr ? variability : "continuous";
    if (md->fmi_major == 3) {
      if (!Dimensions(v, *md, &var.count)) return false;
      if (const char* start = Attr(v, "start")) vr_start_[var.value_reference] = start;
    }
    md->variables.push_back(var);
  }
  return true;
}
}  // namespace

const Variable* ModelDescription::Find(const std::string& name) const {
  for (const Variable& v : variables)
    if (v.name == name) return &v;
  return nullptr;
}

bool ReadFile(const std::string& path, std::string* out, std::string* error) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    *error = path + ": cannot read: " + std::strerror(errno);
    return false;
  }
  char buf[65536];
  size_t n;
  out->clear();
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out->append(buf, n);
  if (std::ferror(f) != 0) *error = path + ": cannot read: " + std::strerror(errno);
  const bool ok = std::ferror(f) == 0;
  std::fclose(f);
  return ok;
}

namespace {
// Parses `text` (named `path` in messages) into the static document (start-up only, one
// file at a time); false with "path:line: XML error" in `error`. `buffer` keeps the text the
// nodes point into.
rapidxml::xml_document<char>* ParseXml(const std::string& path, const std::string& text, std::string* buffer,
                                       std::string* error) {
  *buffer = text;
  buffer->push_back('\0');
  static rapidxml::xml_document<char> doc;
  ParseFailure failure;
  g_failure = &failure;
  if (setjmp(failure.env) != 0) {
    *error = path + ":" + std::to_string(LineOf(*buffer, failure.where)) + ": XML error: " + failure.what;
    return nullptr;
  }
  doc.clear();
  // Lines are counted in the parsed buffer: RapidXML writes terminators but keeps newlines
  // in place, so offsets match the file.
  doc.parse<rapidxml::parse_validate_closing_tags>(&(*buffer)[0]);
  return &doc;
}
rapidxml::xml_document<char>* ParseXmlFile(const std::string& path, std::string* buffer, std::string* error) {
  std::string text;
  if (!ReadFile(path, &text, error)) return nullptr;
  return ParseXml(path, text, buffer, error);
}
}  // namespace

bool ParseModelDescription(const std::string& path, const std::string& text, ModelDescription* out,
                           std::string* error) {
  std::string buffer;
  rapidxml::xml_document<char>* doc = ParseXml(path, text, &buffer, error);
  if (doc == nullptr) return false;
  Parser parser(path, buffer);
  if (!parser.Run(doc->first_node(), out)) {
    *error = parser.error();
    return false;
  }
  return true;
}

bool LoadModelDescription(const std::string& path, ModelDescription* out, std::string* error) {
  std::string text;
  if (!ReadFile(path, &text, error)) return false;
  return ParseModelDescription(path, text, out, error);
}

bool LoadBuildDescription(const std::string& path, const std::string& model_identifier, BuildDescription* out,
                          std::string* error) {
  std::string buffer;
  rapidxml::xml_document<char>* doc = ParseXmlFile(path, &buffer, error);
  if (doc == nullptr) return false;
  Node* root = doc->first_node();
  auto fail = [&](const char* where, const std::string& m) {
    *error = path + ":" + std::to_string(LineOf(buffer, where)) + ": " + m;
    return false;
  };
  if (root == nullptr || std::strcmp(root->name(), "fmiBuildDescription") != 0)
    return fail(root != nullptr ? root->name() : nullptr, "root element is not <fmiBuildDescription>");
  for (Node* bc = root->first_node("BuildConfiguration"); bc != nullptr; bc = bc->next_sibling("BuildConfiguration")) {
    const char* id = Attr(bc, "modelIdentifier");
    if (id == nullptr || model_identifier != id) continue;
    for (Node* set = bc->first_node("SourceFileSet"); set != nullptr; set = set->next_sibling("SourceFileSet")) {
      const char* language = Attr(set, "language");
      if (language != nullptr && std::strcmp(language, "C") != 0 && std::strcmp(language, "C99") != 0)
        return fail(language, std::string("source language \"") + language + "\" is not supported (C is)");
      for (Node* f = set->first_node("SourceFile"); f != nullptr; f = f->next_sibling("SourceFile")) {
        const char* name = Attr(f, "name");
        if (name == nullptr) return fail(f->name(), "<SourceFile> has no name");
        out->sources.push_back(name);
      }
      for (Node* d = set->first_node("PreprocessorDefinition"); d != nullptr;
           d = d->next_sibling("PreprocessorDefinition")) {
        const char* name = Attr(d, "name");
        if (name == nullptr) return fail(d->name(), "<PreprocessorDefinition> has no name");
        const char* value = Attr(d, "value");
        out->defines.push_back(value != nullptr ? std::string(name) + "=" + value : std::string(name));
      }
      for (Node* i = set->first_node("IncludeDirectory"); i != nullptr; i = i->next_sibling("IncludeDirectory")) {
        const char* name = Attr(i, "name");
        if (name == nullptr) return fail(i->name(), "<IncludeDirectory> has no name");
        out->include_dirs.push_back(name);
      }
    }
    if (out->sources.empty()) return fail(bc->name(), "no <SourceFile> for " + model_identifier);
    return true;
  }
  return fail(root->name(), "no <BuildConfiguration modelIdentifier=\"" + model_identifier + "\">");
}

}  // namespace ccomm::fmu
