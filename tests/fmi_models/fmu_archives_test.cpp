// The six test FMUs as archives: read_fmu accepts each (version, model identifier, binary for this
// platform, variables), its binary exports the version's functions and nothing else, and every
// start value of its modelDescription.xml is what the model holds after instantiation.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "cosmic/fmu_archive.hpp"
#include "fmu_driver.hpp"

namespace cosmic::test {
namespace {

using fmi::Causality;
using fmi::VariableType;

struct TestFmu {
  const char* name;
  int version;
};

std::string fmu_label(const testing::TestParamInfo<TestFmu>& info) {
  return std::string(info.param.name) + "Fmi" + std::to_string(info.param.version);
}

const TestFmu kAllTestFmus[] = {{"SpeedController", 2}, {"SpeedController", 3}, {"Plant", 2},
                                {"Plant", 3},           {"EveryType", 2},       {"EveryType", 3}};

class TestFmuArchive : public testing::TestWithParam<TestFmu> {};

TEST_P(TestFmuArchive, ReadFmuAcceptsItWithItsBinaryForThisPlatform) {
  const TestFmu fmu = GetParam();
  const fmi::FmuReadResult read = fmi::read_fmu(test_fmu_path(fmu.name, fmu.version));
  ASSERT_TRUE(read.ok()) << testing::PrintToString(read.errors);
  const fmi::FmuDescription& d = read.contents.description;
  EXPECT_EQ(d.version, fmu.version == 2 ? fmi::FmiVersion::fmi2 : fmi::FmiVersion::fmi3);
  EXPECT_EQ(d.fmi_version, fmu.version == 2 ? "2.0" : "3.0");
  EXPECT_EQ(d.model_name, fmu.name);
  ASSERT_TRUE(d.co_simulation.has_value());
  EXPECT_EQ(d.co_simulation->model_identifier, fmu.name);
  EXPECT_TRUE(d.co_simulation->can_handle_variable_communication_step_size);
  EXPECT_FALSE(d.co_simulation->can_be_instantiated_only_once_per_process);
  EXPECT_FALSE(d.co_simulation->has_event_mode);
  EXPECT_EQ(d.default_experiment.step_size, 0.01);
  const std::string platform = fmu.version == 2 ? "linux64" : "x86_64-linux";
  EXPECT_EQ(read.contents.binary_entry, "binaries/" + platform + "/" + fmu.name + ".so");
  ASSERT_FALSE(d.variables.empty());
  EXPECT_EQ(d.variables[0].name, "time");
  EXPECT_EQ(d.variables[0].causality, Causality::independent);
}

TEST_P(TestFmuArchive, TheBinaryExportsItsVersionsFunctionsOnly) {
  const TestFmu fmu = GetParam();
  LoadedFmu loaded(test_fmu_path(fmu.name, fmu.version));
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  const char* const own[] = {
      "GetVersion", "SetDebugLogging", "FreeInstance", "EnterInitializationMode", "ExitInitializationMode", "Terminate",
      "Reset",      "DoStep",          "GetFloat64"};
  const std::string prefix = fmu.version == 2 ? "fmi2" : "fmi3";
  for (const char* function : own) {
    const std::string name =
        prefix + (fmu.version == 2 && std::string(function) == "GetFloat64" ? "GetReal" : function);
    EXPECT_NE(loaded.symbol(name.c_str()), nullptr) << name;
  }
  EXPECT_EQ(loaded.symbol(fmu.version == 2 ? "fmi3GetVersion" : "fmi2GetVersion"), nullptr);
  // The framework's own functions stay hidden (C_VISIBILITY_PRESET hidden).
  EXPECT_EQ(loaded.symbol("cosmic_fmu_create"), nullptr);
  EXPECT_EQ(loaded.symbol("cosmic_fmu_this_model"), nullptr);
  using GetVersion = const char*();
  EXPECT_STREQ(loaded.function<GetVersion>((prefix + "GetVersion").c_str())(), fmu.version == 2 ? "2.0" : "3.0");
}

// The description's start values as the test reads them: floats, signed and unsigned integers,
// booleans and strings as Value holds them.
Value start_value(const fmi::Variable& v) {
  const std::string& text = v.start.at(0);
  if (fmi::is_float(v.type)) return std::strtod(text.c_str(), nullptr);
  switch (v.type) {
    case VariableType::uint8:
    case VariableType::uint16:
    case VariableType::uint32:
    case VariableType::uint64:
      return std::uint64_t{std::strtoull(text.c_str(), nullptr, 10)};
    case VariableType::boolean:
      return text == "true" || text == "1";
    case VariableType::string:
      return text;
    default:
      return std::int64_t{std::strtoll(text.c_str(), nullptr, 10)};
  }
}

TEST_P(TestFmuArchive, EveryStartValueOfTheDescriptionIsTheModelsOwn) {
  const TestFmu fmu = GetParam();
  LoadedFmu loaded(test_fmu_path(fmu.name, fmu.version));
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  std::unique_ptr<Model> model = Model::instantiate(loaded);
  ASSERT_TRUE(model->instantiated());
  ASSERT_EQ(model->enter_initialization(), Status::ok) << model->log_text();
  int checked = 0;
  for (const fmi::Variable& v : loaded.description().variables) {
    if (v.start.empty()) continue;
    Value held;
    ASSERT_EQ(model->get(v, held), Status::ok) << v.name << "\n" << model->log_text();
    EXPECT_EQ(held, start_value(v)) << v.name;
    ++checked;
  }
  EXPECT_GE(checked, 2);
  // Inputs and parameters have a start value (the standard requires it); outputs are calculated.
  for (const fmi::Variable& v : loaded.description().variables) {
    const bool needs_start = v.causality == Causality::input || v.causality == Causality::parameter;
    EXPECT_EQ(!v.start.empty(), needs_start) << v.name;
  }
}

INSTANTIATE_TEST_SUITE_P(TestFmus, TestFmuArchive, testing::ValuesIn(kAllTestFmus), fmu_label);

}  // namespace
}  // namespace cosmic::test
