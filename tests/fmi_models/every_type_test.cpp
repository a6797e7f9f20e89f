// The EveryType test FMU (every_type.c): each output is the documented function of its input for
// every type of FMI 2.0 and 3.0, the 64-bit extremes included; `fail` makes a step return Error
// with the message passed to the logger; FMI 3.0's scalar count, step report and instantiation
// checks.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "cosmic/fmi3_api.h"
#include "fmu_driver.hpp"

namespace cosmic::test {
namespace {

template <class T>
constexpr T lowest() {
  return std::numeric_limits<T>::lowest();
}
template <class T>
constexpr T highest() {
  return std::numeric_limits<T>::max();
}

// An input value and the output the model must give for it.
struct Case {
  const char* type;  // the variables are <type>_in and <type>_out
  Value in;
  Value out;
};

class EveryTypeFmu : public testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fmu_.ok()) << fmu_.error();
    model_ = Model::instantiate(fmu_);
    ASSERT_TRUE(model_->instantiated());
    ASSERT_EQ(model_->enter_initialization(), Status::ok);
    ASSERT_EQ(model_->exit_initialization(), Status::ok) << model_->log_text();
  }

  // Sets every input of `cases`, steps once, and compares every output.
  void expect_outputs(const std::vector<Case>& cases) {
    for (const Case& c : cases) ASSERT_EQ(model_->set(std::string(c.type) + "_in", c.in), Status::ok) << c.type;
    ASSERT_EQ(model_->do_step(time_, 0.01), Status::ok) << model_->log_text();
    time_ += 0.01;
    for (const Case& c : cases) EXPECT_EQ(model_->get(std::string(c.type) + "_out"), c.out) << c.type;
  }

  LoadedFmu fmu_{test_fmu_path("EveryType", GetParam())};
  std::unique_ptr<Model> model_;
  double time_ = 0.0;
};

// The enumeration Gear: park 0, reverse -1, neutral 1, drive 2; each is followed by the next.
const std::vector<Case> kGearCases = {{"enumeration", std::int64_t{0}, std::int64_t{-1}},
                                      {"enumeration", std::int64_t{-1}, std::int64_t{1}},
                                      {"enumeration", std::int64_t{1}, std::int64_t{2}},
                                      {"enumeration", std::int64_t{2}, std::int64_t{0}}};

TEST_P(EveryTypeFmu, TheEnumerationOutputIsTheNextItemCyclically) {
  for (const Case& c : kGearCases) expect_outputs({c});
}

TEST_P(EveryTypeFmu, BooleanAndStringOutputs) {
  expect_outputs({{"boolean", true, false}, {"string", std::string("gear"), std::string("gear!")}});
  expect_outputs({{"boolean", false, true}, {"string", std::string(""), std::string("!")}});
  // A '%' is text, not a format, on the way in and out.
  expect_outputs({{"string", std::string("100% sure"), std::string("100% sure!")}});
}

TEST_P(EveryTypeFmu, AStringInputIsCopiedAndAReadStringStaysValidUntilTheNextCall) {
  std::string buffer = "abc";
  ASSERT_EQ(model_->set("string_in", buffer), Status::ok);
  buffer = "xyz";  // the model keeps its copy
  ASSERT_EQ(model_->do_step(0.0, 0.01), Status::ok);
  EXPECT_EQ(model_->get("string_in"), Value(std::string("abc")));
  EXPECT_EQ(model_->get("string_out"), Value(std::string("abc!")));
}

TEST_P(EveryTypeFmu, FailMakesTheStepAnErrorWithTheMessageGivenToTheLogger) {
  expect_outputs({{"boolean", true, false}});
  ASSERT_EQ(model_->set("fail", true), Status::ok);
  model_->clear_log();
  EXPECT_EQ(model_->do_step(0.01, 0.01), Status::error);
  ASSERT_EQ(model_->log().size(), 1u) << model_->log_text();
  EXPECT_EQ(model_->log()[0].status, Status::error);
  EXPECT_EQ(model_->log()[0].category, "logStatusError");
  EXPECT_EQ(model_->log()[0].message, "step at t=0.01 failed: the fail input is set");
  // The outputs are those of the last good step; the instance no longer steps until reset.
  EXPECT_EQ(model_->get("boolean_out"), Value(false));
  EXPECT_EQ(model_->do_step(0.02, 0.01), Status::error);
  EXPECT_EQ(model_->terminate(), Status::ok);
  ASSERT_EQ(model_->reset(), Status::ok);
  ASSERT_EQ(model_->enter_initialization(), Status::ok);
  EXPECT_EQ(model_->get("fail"), Value(false));
  ASSERT_EQ(model_->exit_initialization(), Status::ok);
  EXPECT_EQ(model_->do_step(0.0, 0.01), Status::ok);
}

TEST_P(EveryTypeFmu, AValueThatIsNoItemFailsTheStep) {
  ASSERT_EQ(model_->set("enumeration_in", std::int64_t{7}), Status::ok);
  EXPECT_EQ(model_->do_step(0.0, 0.01), Status::error);
  ASSERT_FALSE(model_->log().empty());
  EXPECT_EQ(model_->log()[0].message,
            "enumeration_in is 7, not an item of Gear (park 0, reverse -1, neutral 1, drive 2)");
}

TEST_P(EveryTypeFmu, WithoutLoggingNothingIsLogged) {
  std::unique_ptr<Model> quiet = Model::instantiate(fmu_, "quiet", false);
  EXPECT_EQ(quiet->do_step(0.0, 0.01), Status::error);
  EXPECT_TRUE(quiet->log().empty()) << quiet->log_text();
}

INSTANTIATE_TEST_SUITE_P(Versions, EveryTypeFmu, testing::Values(2, 3), fmi_version_label);

class EveryTypeFmi2 : public EveryTypeFmu {};

TEST_P(EveryTypeFmi2, RealAndIntegerOutputsAtTheirLimits) {
  expect_outputs({{"real", 1.25, 2.5}, {"integer", std::int64_t{41}, std::int64_t{42}}});
  expect_outputs({{"real", -1e300, -2e300}, {"integer", std::int64_t{-1}, std::int64_t{0}}});
  // Integer is 32 bits: the largest wraps to the smallest.
  expect_outputs({{"real", highest<double>(), std::numeric_limits<double>::infinity()},
                  {"integer", std::int64_t{highest<std::int32_t>()}, std::int64_t{lowest<std::int32_t>()}}});
  expect_outputs({{"integer", std::int64_t{lowest<std::int32_t>()}, std::int64_t{lowest<std::int32_t>() + 1}}});
}

INSTANTIATE_TEST_SUITE_P(Fmi2, EveryTypeFmi2, testing::Values(2), fmi_version_label);

class EveryTypeFmi3 : public EveryTypeFmu {};

TEST_P(EveryTypeFmi3, FloatOutputsAreTwiceTheInput) {
  expect_outputs({{"float32", 1.25, 2.5}, {"float64", -3.5, -7.0}});
  expect_outputs({{"float32", double{highest<float>()}, std::numeric_limits<double>::infinity()},
                  {"float64", 1e-310, 2.0 * 1e-310}});
}

TEST_P(EveryTypeFmi3, IntegerOutputsAreTheInputPlusOneWrappingAtTheLimits) {
  expect_outputs({{"int8", std::int64_t{-8}, std::int64_t{-7}},
                  {"uint8", std::uint64_t{8}, std::uint64_t{9}},
                  {"int16", std::int64_t{-300}, std::int64_t{-299}},
                  {"uint16", std::uint64_t{300}, std::uint64_t{301}},
                  {"int32", std::int64_t{-70000}, std::int64_t{-69999}},
                  {"uint32", std::uint64_t{70000}, std::uint64_t{70001}},
                  {"int64", std::int64_t{-5'000'000'000}, std::int64_t{-4'999'999'999}},
                  {"uint64", std::uint64_t{5'000'000'000}, std::uint64_t{5'000'000'001}}});
  expect_outputs({{"int8", std::int64_t{highest<std::int8_t>()}, std::int64_t{lowest<std::int8_t>()}},
                  {"uint8", std::uint64_t{highest<std::uint8_t>()}, std::uint64_t{0}},
                  {"int16", std::int64_t{highest<std::int16_t>()}, std::int64_t{lowest<std::int16_t>()}},
                  {"uint16", std::uint64_t{highest<std::uint16_t>()}, std::uint64_t{0}},
                  {"int32", std::int64_t{highest<std::int32_t>()}, std::int64_t{lowest<std::int32_t>()}},
                  {"uint32", std::uint64_t{highest<std::uint32_t>()}, std::uint64_t{0}},
                  {"int64", highest<std::int64_t>(), lowest<std::int64_t>()},
                  {"uint64", highest<std::uint64_t>(), std::uint64_t{0}}});
  expect_outputs({{"int8", std::int64_t{lowest<std::int8_t>()}, std::int64_t{lowest<std::int8_t>() + 1}},
                  {"int64", lowest<std::int64_t>(), lowest<std::int64_t>() + 1},
                  {"uint64", highest<std::uint64_t>() - 1, highest<std::uint64_t>()}});
}

TEST_P(EveryTypeFmi3, SixtyFourBitOutputsCarryValuesBeyondTwoToThe53Exactly) {
  // 2^53 + 1 is no double: a path through floating point would give 2^53 or 2^53 + 2.
  const std::uint64_t beyond = (std::uint64_t{1} << 53) + 1;
  expect_outputs({{"uint64", beyond, beyond + 1},
                  {"int64", -static_cast<std::int64_t>(beyond) - 2, -static_cast<std::int64_t>(beyond) - 1}});
}

TEST_P(EveryTypeFmi3, DoStepReportsNoEventNoEarlyReturnAndTheEndOfTheStep) {
  ASSERT_EQ(model_->do_step(0.0, 0.01), Status::ok);
  const Fmi3StepReport& report = last_step_report(*model_);
  EXPECT_FALSE(report.event_handling_needed);
  EXPECT_FALSE(report.terminate_simulation);
  EXPECT_FALSE(report.early_return);
  EXPECT_EQ(report.last_successful_time, 0.01);
  ASSERT_EQ(model_->set("fail", true), Status::ok);
  EXPECT_EQ(model_->do_step(0.01, 0.01), Status::error);
  EXPECT_EQ(last_step_report(*model_).last_successful_time, 0.01);
}

TEST_P(EveryTypeFmi3, ValuesAndValueReferencesMustBeAsMany) {
  auto* get = fmu_.function<fmi3GetUInt64TYPE>("fmi3GetUInt64");
  const fmi3ValueReference vr[] = {fmu_.variable("uint64_out")->value_reference};
  fmi3UInt64 values[2] = {};
  model_->clear_log();
  EXPECT_EQ(get(model_->instance(), vr, 1, values, 2), fmi3Error);
  ASSERT_EQ(model_->log().size(), 1u);
  EXPECT_EQ(model_->log()[0].message, "fmi3GetUInt64: 2 values for 1 value references (every variable is a scalar)");
  EXPECT_EQ(get(model_->instance(), vr, 1, values, 1), fmi3OK);
}

TEST_P(EveryTypeFmi3, EventModeIsRefusedAtInstantiation) {
  std::unique_ptr<Model> refused = instantiate_fmi3(fmu_, "events", true, true);
  EXPECT_FALSE(refused->instantiated());
  ASSERT_EQ(refused->log().size(), 1u);
  EXPECT_EQ(refused->log()[0].message,
            "fmi3InstantiateCoSimulation: this FMU has no event mode (hasEventMode is false)");
}

INSTANTIATE_TEST_SUITE_P(Fmi3, EveryTypeFmi3, testing::Values(3), fmi_version_label);

}  // namespace
}  // namespace cosmic::test
