// SPDX-License-Identifier: Apache-2.0
// ccomm-fmu's parsers: modelDescription.xml (what is read, what is refused and where) and
// the mapping file.
#include <gtest/gtest.h>

#include "mapping.h"
#include "model_description.h"

namespace ccomm::fmu {
namespace {

const char kFmi3[] = R"(<?xml version="1.0"?>
<fmiModelDescription fmiVersion="3.0" modelName="m" instantiationToken="{t}">
  <CoSimulation modelIdentifier="m" fixedInternalStepSize="0.0005"/>
  <DefaultExperiment stepSize="0.001"/>
  <ModelVariables>
    <UInt64 name="n" valueReference="9" causality="structuralParameter" variability="fixed" start="3"/>
    <Float64 name="u" valueReference="1" causality="input"/>
    <Float32 name="a" valueReference="2" causality="output"><Dimension start="2"/><Dimension valueReference="9"/></Float32>
    <Int8 name="small" valueReference="3" causality="input"/>
    <Float64 name="k" valueReference="4" causality="parameter" variability="tunable" start="1"/>
  </ModelVariables>
</fmiModelDescription>
)";

TEST(ModelDescription, ReadsFmi3) {
  ModelDescription md;
  std::string error;
  ASSERT_TRUE(ParseModelDescription("md.xml", kFmi3, &md, &error)) << error;
  EXPECT_EQ(md.fmi_major, 3);
  EXPECT_EQ(md.model_identifier, "m");
  EXPECT_EQ(md.token, "{t}");
  EXPECT_DOUBLE_EQ(md.default_step, 0.001);
  EXPECT_DOUBLE_EQ(md.fixed_internal_step, 0.0005);
  const Variable* a = md.Find("a");
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->type, FmiType::kFloat32);
  EXPECT_EQ(a->count, 6u);  // 2 x n (n = 3)
  EXPECT_EQ(a->causality, Causality::kOutput);
  EXPECT_EQ(a->line, 8);
  EXPECT_EQ(md.Find("small")->type, FmiType::kOther);
  EXPECT_EQ(md.Find("k")->variability, "tunable");
}

std::string Refusal(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  ModelDescription md;
  std::string error;
  EXPECT_FALSE(ParseModelDescription("md.xml", text, &md, &error));
  return error;
}

TEST(ModelDescription, RefusesWithFileAndLine) {
  EXPECT_EQ(Refusal(kFmi3, "name=\"k\"", "name=\"u\""), "md.xml:10: variable \"u\" defined twice");
  EXPECT_EQ(Refusal(kFmi3, "valueReference=\"4\"", "valueReference=\"1\""), "md.xml:10: valueReference 1 used twice");
  EXPECT_EQ(Refusal(kFmi3, "<CoSimulation", "<ModelExchange"),
            "md.xml:2: the FMU has no <CoSimulation> interface (model exchange and scheduled execution are not "
            "supported)");
  EXPECT_EQ(Refusal(kFmi3, "fmiVersion=\"3.0\"", "fmiVersion=\"1.0\""),
            "md.xml:2: fmiVersion \"1.0\" is not supported (2.0 and 3.x are)");
  EXPECT_EQ(Refusal(kFmi3, "<Dimension valueReference=\"9\"/>", "<Dimension valueReference=\"7\"/>"),
            "md.xml:8: Dimension valueReference 7 is not an earlier structural parameter with an integer start");
  EXPECT_EQ(Refusal(kFmi3, "causality=\"input\"/>", "causality=\"sideways\"/>"),
            "md.xml:7: unknown causality \"sideways\"");
  EXPECT_EQ(Refusal(kFmi3, "modelIdentifier=\"m\"", "modelIdentifier=\"../m\""),
            "md.xml:3: modelIdentifier is not a plain file name");
  EXPECT_EQ(Refusal(kFmi3, "</ModelVariables>", "</ModelVariable>").substr(0, 24), "md.xml:11: XML error: in");  // "invalid closing tag name"
}

TEST(ModelDescription, ReadsFmi2ScalarVariables) {
  const char text[] = R"(<fmiModelDescription fmiVersion="2.0" modelName="c" guid="{g}">
<CoSimulation modelIdentifier="c"><SourceFiles><File name="c.c"/></SourceFiles></CoSimulation>
<ModelVariables>
<ScalarVariable name="r" valueReference="0" causality="input"><Real/></ScalarVariable>
<ScalarVariable name="i" valueReference="0" causality="output"><Integer/></ScalarVariable>
<ScalarVariable name="b" valueReference="0" causality="output"><Boolean/></ScalarVariable>
</ModelVariables></fmiModelDescription>)";
  ModelDescription md;
  std::string error;
  ASSERT_TRUE(ParseModelDescription("md.xml", text, &md, &error)) << error;  // value references per type
  EXPECT_EQ(md.fmi_major, 2);
  EXPECT_EQ(md.token, "{g}");
  ASSERT_EQ(md.source_files.size(), 1u);
  EXPECT_EQ(md.Find("r")->type, FmiType::kFloat64);
  EXPECT_EQ(md.Find("i")->type, FmiType::kInt32);
  EXPECT_EQ(md.Find("b")->type, FmiType::kBool);
  EXPECT_EQ(md.Find("b")->line, 6);
}

TEST(Mapping, ReadsLines) {
  std::vector<MappingLine> lines;
  std::string error;
  ASSERT_TRUE(ParseMapping("f.map", "# c\n  y = out.sig  # why\nok = fresh( in )\nz = -\n\n", &lines, &error)) << error;
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].variable, "y");
  EXPECT_EQ(lines[0].signal, "out.sig");
  EXPECT_EQ(lines[0].line, 2);
  EXPECT_TRUE(lines[1].freshness);
  EXPECT_EQ(lines[1].signal, "in");
  EXPECT_TRUE(lines[2].signal.empty());
}

TEST(Mapping, RefusesWithFileAndLine) {
  auto refusal = [](const char* text) {
    std::vector<MappingLine> lines;
    std::string error;
    EXPECT_FALSE(ParseMapping("f.map", text, &lines, &error));
    return error;
  };
  EXPECT_EQ(refusal("a = b\n\na c\n"), "f.map:3: expected '<fmu variable> = <signal>', got \"a c\"");
  EXPECT_EQ(refusal("a = b\na = c\n"), "f.map:2: variable \"a\" mapped twice");
  EXPECT_EQ(refusal("a = fresh(-)\n"), "f.map:1: \"-\" is not a signal name (or fresh(<signal>), or - for not connected)");
  EXPECT_EQ(refusal(" = b\n"), "f.map:1: \"\" is not an FMU variable name");
  EXPECT_EQ(refusal("a = b c\n"), "f.map:1: \"b c\" is not a signal name (or fresh(<signal>), or - for not connected)");
}

}  // namespace
}  // namespace ccomm::fmu
