// modelDescription.xml of FMI 2.0 and 3.0 (cosmic/fmi_description.hpp): every variable type and
// causality read with its reference, start, unit and declared type; co-simulation flags and the
// default experiment; and every refusal with its line.
#include <gtest/gtest.h>

#include "cosmic/fmi_description.hpp"
#include "fmu_test_support.hpp"

namespace cosmic::fmi {
namespace {

std::string problems_text(const DescriptionResult& r) {
  std::string out;
  for (const auto& p : r.problems) out += p.to_string() + "\n";
  return out;
}

TEST(FmiDescription, Fmi2EveryTypeAndCausality) {
  const DescriptionResult r = parse_model_description(test::kFmi2Description);
  ASSERT_TRUE(r.ok()) << problems_text(r);
  const FmuDescription& d = r.description;
  EXPECT_EQ(d.version, FmiVersion::fmi2);
  EXPECT_EQ(d.fmi_version, "2.0");
  EXPECT_EQ(d.model_name, "Plant");
  EXPECT_EQ(d.instantiation_token, "{8c4e810f-3df3-4a00-8276-176fa3c9f000}");
  ASSERT_TRUE(d.co_simulation);
  EXPECT_EQ(d.co_simulation->model_identifier, "Plant");
  EXPECT_TRUE(d.co_simulation->can_handle_variable_communication_step_size);
  EXPECT_FALSE(d.model_exchange);
  EXPECT_EQ(d.default_experiment.step_size, 0.01);
  EXPECT_EQ(d.default_experiment.stop_time, 10.0);
  EXPECT_EQ(d.default_experiment.tolerance, 1e-6);
  ASSERT_EQ(d.variables.size(), 10u);

  const Variable* u = d.find_variable("u");
  ASSERT_NE(u, nullptr);
  EXPECT_EQ(u->type, VariableType::float64);
  EXPECT_EQ(u->causality, Causality::input);
  EXPECT_EQ(u->variability, Variability::continuous);
  EXPECT_EQ(u->value_reference, 1u);
  EXPECT_EQ(u->declared_type, "Speed");
  EXPECT_EQ(u->unit, "m/s");  // from the declared type
  EXPECT_EQ(u->min, -20.0);
  EXPECT_EQ(u->start, std::vector<std::string>{"0"});
  EXPECT_EQ(u->line, 11);

  const Variable* count = d.find_variable("count");
  EXPECT_EQ(count->type, VariableType::int32);
  EXPECT_EQ(count->variability, Variability::discrete);  // the default of a type other than Real
  EXPECT_EQ(count->max, 200.0);
  EXPECT_EQ(d.find_variable("ready")->type, VariableType::boolean);
  EXPECT_EQ(d.find_variable("label")->type, VariableType::string);
  EXPECT_EQ(d.find_variable("label")->start, std::vector<std::string>{"plant"});
  EXPECT_EQ(d.find_variable("mode")->type, VariableType::enumeration);
  ASSERT_NE(d.find_type("Mode"), nullptr);
  EXPECT_EQ(d.find_type("Mode")->items, (std::vector<EnumerationItem>{{"off", 1}, {"on", 2}}));
  EXPECT_EQ(d.find_variable("gain")->variability, Variability::tunable);
  EXPECT_EQ(d.find_variable("x")->causality, Causality::local);
  EXPECT_EQ(d.find_variable("time")->causality, Causality::independent);
  EXPECT_EQ(d.find_variable("twice")->causality, Causality::calculated_parameter);
  EXPECT_EQ(type_element(VariableType::float64, FmiVersion::fmi2), "Real");
  EXPECT_EQ(type_element(VariableType::int32, FmiVersion::fmi2), "Integer");
}

TEST(FmiDescription, Fmi3EveryTypeArraysAndAliases) {
  const DescriptionResult r = parse_model_description(test::kFmi3Description);
  ASSERT_TRUE(r.ok()) << problems_text(r);
  const FmuDescription& d = r.description;
  EXPECT_EQ(d.version, FmiVersion::fmi3);
  EXPECT_EQ(d.instantiation_token, "{every}");
  ASSERT_TRUE(d.co_simulation);
  EXPECT_TRUE(d.co_simulation->has_event_mode);
  EXPECT_EQ(d.co_simulation->fixed_internal_step_size, 0.001);
  EXPECT_EQ(d.default_experiment.step_size, 0.005);
  const std::vector<std::pair<std::string, VariableType>> types = {
      {"f32", VariableType::float32}, {"angle", VariableType::float64},    {"i8", VariableType::int8},
      {"u8", VariableType::uint8},    {"i16", VariableType::int16},        {"u16", VariableType::uint16},
      {"i32", VariableType::int32},   {"u32", VariableType::uint32},       {"i64", VariableType::int64},
      {"u64", VariableType::uint64},  {"flag", VariableType::boolean},     {"text", VariableType::string},
      {"blob", VariableType::binary}, {"gear", VariableType::enumeration}, {"tick", VariableType::clock}};
  for (const auto& [name, type] : types) {
    const Variable* v = d.find_variable(name);
    ASSERT_NE(v, nullptr) << name;
    EXPECT_EQ(v->type, type) << name;
    EXPECT_EQ(type_element(type, FmiVersion::fmi3), std::string(type_element(v->type, FmiVersion::fmi3)));
  }
  EXPECT_EQ(d.find_variable("f32")->variability, Variability::continuous);
  EXPECT_EQ(d.find_variable("i8")->variability, Variability::discrete);
  EXPECT_EQ(d.find_variable("angle")->unit, "rad");
  EXPECT_EQ(d.find_variable("u64")->start, std::vector<std::string>{"18446744073709551615"});
  EXPECT_EQ(d.find_variable("text")->start, std::vector<std::string>{"hello world"});
  const Variable* heading = d.find_variable("heading");
  ASSERT_NE(heading, nullptr);
  EXPECT_EQ(heading->alias_of, "angle");
  EXPECT_EQ(heading->value_reference, 2u);
  EXPECT_EQ(d.find_variable("n")->causality, Causality::structural_parameter);
  const Variable* vector = d.find_variable("vector");
  ASSERT_EQ(vector->dimensions.size(), 1u);
  EXPECT_EQ(vector->dimensions[0].value_reference, 16u);
  EXPECT_EQ(vector->start, std::vector<std::string>{"1 2 3"});
  EXPECT_EQ(d.find_type("Gear")->items.size(), 3u);
}

// A 2.0 document around `variables` (line 5 on), with `root` attributes and `co` as its interface.
std::string fmi2(const std::string& variables, const std::string& co = "<CoSimulation modelIdentifier=\"M\"/>",
                 const std::string& root = "fmiVersion=\"2.0\" modelName=\"M\" guid=\"g\"") {
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription " + root + ">\n" + co + "\n<ModelVariables>\n" + variables +
         "</ModelVariables>\n</fmiModelDescription>\n";
}

std::string fmi3(const std::string& variables) {
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"3.0\" modelName=\"M\" instantiationToken=\"t\">\n"
         "<CoSimulation modelIdentifier=\"M\"/>\n<ModelVariables>\n" +
         variables + "</ModelVariables>\n</fmiModelDescription>\n";
}

TEST(FmiDescription, EveryRefusalWithItsLine) {
  struct Case {
    std::string xml;
    std::string expected;
  };
  const std::string real = "<Real/></ScalarVariable>\n";
  const std::vector<Case> cases = {
      {"<fmiModelDescription fmiVersion=\"2.0\">\n<CoSimulation", "modelDescription.xml:2: malformed XML"},
      {"<?xml version=\"1.0\"?>\n<model/>", "modelDescription.xml:2: the root element is <model>"},
      {fmi2("", "", "fmiVersion=\"1.0\" modelName=\"M\" guid=\"g\""),
       "modelDescription.xml:2: fmiVersion \"1.0\" is not supported (2.0 or 3.x)"},
      {fmi2("", "", "fmiVersion=\"3.0-beta.2\" modelName=\"M\" instantiationToken=\"t\""),
       "fmiVersion \"3.0-beta.2\" is not supported"},
      {fmi2("", "<CoSimulation modelIdentifier=\"M\"/>", "fmiVersion=\"2.0\" modelName=\"M\""),
       "modelDescription.xml:2: <fmiModelDescription> lacks the required attribute 'guid'"},
      {fmi2("", "<CoSimulation/>"),
       "modelDescription.xml:3: <CoSimulation> lacks the required attribute 'modelIdentifier'"},
      {fmi2("", "<ModelExchange modelIdentifier=\"M\"/>"),
       "modelDescription.xml:2: no <CoSimulation> element: the FMU is for model exchange only"},
      {fmi2("<ScalarVariable valueReference=\"1\">" + real),
       "modelDescription.xml:5: <ScalarVariable> lacks the required attribute 'name'"},
      {fmi2("<ScalarVariable name=\"a\">" + real),
       "modelDescription.xml:5: <ScalarVariable> lacks the required attribute 'valueReference'"},
      {fmi2("<ScalarVariable name=\"a\" valueReference=\"x1\">" + real), "valueReference=\"x1\" is not a whole number"},
      {fmi2("<ScalarVariable name=\"a\" valueReference=\"1\">" + real +
            "<ScalarVariable name=\"a\" valueReference=\"2\">" + real),
       "modelDescription.xml:6: variable name 'a' used twice (first at line 5)"},
      {fmi2("<ScalarVariable name=\"a\" valueReference=\"1\"><Integer/></ScalarVariable>\n"
            "<ScalarVariable name=\"b\" valueReference=\"1\"><Enumeration declaredType=\"E\"/></ScalarVariable>\n"),
       "modelDescription.xml:6: variable 'b' (Enumeration): valueReference 1 is also 'a''s (Integer, line 5)"},
      {fmi3("<Float64 name=\"a\" valueReference=\"1\"/>\n<Int32 name=\"b\" valueReference=\"1\"/>\n"),
       "modelDescription.xml:6: variable 'b': valueReference 1 is also 'a''s (line 5)"},
      {fmi2("<ScalarVariable name=\"a\" valueReference=\"1\"><Float64/></ScalarVariable>\n"),
       "modelDescription.xml:5: unknown type element <Float64> (one of Real, Integer, Boolean, String, Enumeration)"},
      {fmi3("<Float128 name=\"a\" valueReference=\"1\"/>\n"),
       "modelDescription.xml:5: unknown variable type element <Float128>"},
      {fmi2("<ScalarVariable name=\"a\" valueReference=\"1\" causality=\"structuralParameter\">" + real),
       "modelDescription.xml:5: unknown causality \"structuralParameter\""},
      {fmi2("<ScalarVariable name=\"a\" valueReference=\"1\" variability=\"sometimes\">" + real),
       "modelDescription.xml:5: unknown variability \"sometimes\""},
      {fmi2("<ScalarVariable name=\"a\" valueReference=\"1\"><Enumeration/></ScalarVariable>\n"),
       "modelDescription.xml:5: variable 'a': an Enumeration needs a declaredType"},
      {fmi3("<Float64 name=\"a\" valueReference=\"1\" declaredType=\"Nope\"/>\n"),
       "modelDescription.xml:5: variable 'a': declaredType 'Nope' names no Float64 type"},
      {fmi3("<Int32 name=\"a\" valueReference=\"1\"><Dimension/></Int32>\n"),
       "modelDescription.xml:5: <Dimension> needs exactly one of 'start' and 'valueReference'"},
      {fmi2("", "<CoSimulation modelIdentifier=\"M\" canHandleVariableCommunicationStepSize=\"yes\"/>"),
       "modelDescription.xml:3: canHandleVariableCommunicationStepSize=\"yes\" is not a boolean"},
  };
  for (const Case& c : cases) {
    const DescriptionResult r = parse_model_description(c.xml);
    EXPECT_FALSE(r.ok()) << c.expected;
    EXPECT_NE(problems_text(r).find(c.expected), std::string::npos) << "want: " << c.expected << "\ngot:\n"
                                                                    << problems_text(r);
  }
}

TEST(FmiDescription, BoundedTextVariablesAndReportedProblems) {
  EXPECT_NE(problems_text(parse_model_description(std::string(kMaxDescriptionBytes + 1, ' ')))
                .find("more than the " + std::to_string(kMaxDescriptionBytes) + " read"),
            std::string::npos);
  std::string many;
  for (std::size_t i = 0; i <= kMaxVariables; ++i)
    many += "<Float64 name=\"v" + std::to_string(i) + "\" valueReference=\"" + std::to_string(i) + "\"/>\n";
  const DescriptionResult r = parse_model_description(fmi3(many));
  EXPECT_NE(problems_text(r).find("more than " + std::to_string(kMaxVariables) + " variables"), std::string::npos);
  std::string bad;
  for (int i = 0; i < 80; ++i) bad += "<Float64 name=\"v\" valueReference=\"z\"/>\n";
  const DescriptionResult capped = parse_model_description(fmi3(bad));
  ASSERT_EQ(capped.problems.size(), kMaxReportedProblems + 1);
  EXPECT_NE(capped.problems.back().message.find("more problems not shown"), std::string::npos);
}

}  // namespace
}  // namespace cosmic::fmi
