// The runner's FMI layer (cosmic/fmu_instance.hpp: dlopen, the FMI 2.0 and 3.0 calls) against the
// test FMUs, which were written against the standard independently of it: every variable type set
// and read back through the runner's own calls, parameters, initialization refused with the FMU's
// message, and a library that is no FMU.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <limits>

#include "cosmic/fmu_archive.hpp"
#include "cosmic/fmu_instance.hpp"
#include "fmu_driver.hpp"

namespace cosmic::fmi {
namespace {

namespace fs = std::filesystem;

class RunnerInstance : public testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("runner_instance_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The test FMU opened and instantiated by the runner's code.
  std::unique_ptr<FmuInstance> open(std::string_view name) {
    auto opened = open_fmu(test::test_fmu_path(name, GetParam()), (dir_ / std::string(name)).string());
    EXPECT_TRUE(opened.ok()) << (opened.ok() ? "" : opened.errors.front());
    if (!opened.ok()) return nullptr;
    fmu_ = opened.fmu;
    auto instance = instantiate(fmu_, {std::string(name) + "-under-test", true});
    EXPECT_TRUE(instance) << (instance ? "" : instance.error().text);
    return instance ? std::move(instance.value()) : nullptr;
  }
  const Variable& variable(const std::string& name) const {
    const Variable* v = fmu_.description.find_variable(name);
    EXPECT_NE(v, nullptr) << name;
    return *v;
  }

  fs::path dir_;
  OpenedFmu fmu_;
};

TEST_P(RunnerInstance, EveryTypeCrossesTheRunnersCalls) {
  auto fmu = open("EveryType");
  ASSERT_TRUE(fmu);
  ASSERT_TRUE(fmu->initialize(0.0));
  struct Case {
    std::string in, out;
    VariableValue given, expected;
  };
  const std::uint64_t beyond_double = (1ull << 53) + 1;  // a double cannot hold it: must cross exactly
  std::vector<Case> cases;
  if (GetParam() == 2) {
    cases = {{"real", "real", 1.25, 2.5},
             {"integer", "integer", std::int64_t{-7}, std::int64_t{-6}},
             {"boolean", "boolean", true, false},
             {"string", "string", std::string("hi"), std::string("hi!")},
             {"enumeration", "enumeration", std::int64_t{2}, std::int64_t{0}}};
  } else {
    cases = {{"float32", "float32", 0.75, 1.5},
             {"float64", "float64", -3.5, -7.0},
             {"int8", "int8", std::int64_t{127}, std::int64_t{-128}},
             {"uint8", "uint8", std::uint64_t{200}, std::uint64_t{201}},
             {"int16", "int16", std::int64_t{-300}, std::int64_t{-299}},
             {"uint16", "uint16", std::uint64_t{65535}, std::uint64_t{0}},
             {"int32", "int32", std::int64_t{-70000}, std::int64_t{-69999}},
             {"uint32", "uint32", std::uint64_t{4000000000u}, std::uint64_t{4000000001u}},
             {"int64", "int64", std::int64_t{-static_cast<std::int64_t>(beyond_double)},
              std::int64_t{-static_cast<std::int64_t>(beyond_double) + 1}},
             {"uint64", "uint64", beyond_double, beyond_double + 1},
             {"boolean", "boolean", false, true},
             {"string", "string", std::string(""), std::string("!")},
             {"enumeration", "enumeration", std::int64_t{-1}, std::int64_t{1}}};
  }
  for (const auto& c : cases) ASSERT_TRUE(fmu->set(variable(c.in + "_in"), c.given)) << c.in;
  ASSERT_TRUE(fmu->do_step(0.0, 0.01));
  for (const auto& c : cases) {
    auto value = fmu->get(variable(c.out + "_out"));
    ASSERT_TRUE(value) << c.out << ": " << value.error().text;
    EXPECT_EQ(value.value(), c.expected) << c.out << ": " << to_string(value.value());
  }
}

TEST_P(RunnerInstance, AFailedStepNamesTheCallAndKeepsTheFmusMessages) {
  auto fmu = open("EveryType");
  ASSERT_TRUE(fmu);
  ASSERT_TRUE(fmu->initialize(0.0));
  ASSERT_TRUE(fmu->set(variable("fail"), true));
  const auto stepped = fmu->do_step(0.5, 0.01);
  ASSERT_FALSE(stepped);
  const std::string call = GetParam() == 2 ? "fmi2DoStep" : "fmi3DoStep";
  EXPECT_EQ(stepped.error().text, call + " returned Error; the FMU said: step at t=0.5 failed: the fail input is set");
  EXPECT_NE(fmu->recent_log_text().find("[Error] logStatusError: step at t=0.5 failed"), std::string::npos)
      << fmu->recent_log_text();
  EXPECT_TRUE(fmu->terminate());  // after a failure nothing more is called on it
}

TEST_P(RunnerInstance, ParametersAreSetBeforeInitializationAndCheckedByTheFmu) {
  auto fmu = open("Plant");
  ASSERT_TRUE(fmu);
  ASSERT_TRUE(fmu->set(variable("time_constant"), 0.0));
  const auto initialized = fmu->initialize(0.0);
  ASSERT_FALSE(initialized);
  EXPECT_NE(initialized.error().text.find("time_constant must be a number of seconds > 0, not 0"), std::string::npos)
      << initialized.error().text;
}

TEST_P(RunnerInstance, ThePlantStepsAsItsEquationSays) {
  auto fmu = open("Plant");
  ASSERT_TRUE(fmu);
  ASSERT_TRUE(fmu->set(variable("gain"), 3.0));
  ASSERT_TRUE(fmu->initialize(0.0));
  ASSERT_TRUE(fmu->set(variable("drive"), 1.0));
  for (int k = 0; k < 50; ++k) ASSERT_TRUE(fmu->do_step(k * 0.01, 0.01));
  const auto speed = fmu->get(variable("speed"));
  ASSERT_TRUE(speed);
  EXPECT_NEAR(std::get<double>(speed.value()), 3.0 * (1 - std::exp(-0.5 / 0.5)), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Versions, RunnerInstance, testing::Values(2, 3), test::fmi_version_label);

TEST(RunnerInstanceLibrary, ALibraryWithoutTheFunctionsIsRefusedByName) {
  const fs::path dir = fs::path(testing::TempDir()) / ("runner_library_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  auto opened = open_fmu(test::test_fmu_path("Plant", 2), dir.string());
  ASSERT_TRUE(opened.ok());
  // The test FMU's binary replaced by a library that exports no fmi2 functions.
  const fs::path foreign = dir / "foreign.so";
  fs::copy_file("/lib/x86_64-linux-gnu/libm.so.6", foreign);
  opened.fmu.binary = foreign.string();
  const auto instance = instantiate(opened.fmu, {"foreign", true});
  ASSERT_FALSE(instance);
  EXPECT_EQ(instance.error().text,
            foreign.string() + " does not export fmi2GetVersion (an FMI function co-simulation needs)");
  opened.fmu.binary = (dir / "missing.so").string();
  EXPECT_NE(instantiate(opened.fmu, {"missing", true}).error().text.find("cannot load the FMU's binary"),
            std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cosmic::fmi
