// The Plant test FMU (plant.c), FMI 2.0 and 3.0 alike: its step response is the analytic one for
// any step size, a non-positive time constant is refused with its message, a step before
// initialization is refused, and instances do not share state.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "fmu_driver.hpp"

namespace cosmic::test {
namespace {

class PlantFmu : public testing::TestWithParam<int> {
 protected:
  void SetUp() override { ASSERT_TRUE(fmu_.ok()) << fmu_.error(); }
  const char* do_step_name() const { return GetParam() == 2 ? "fmi2DoStep" : "fmi3DoStep"; }
  LoadedFmu fmu_{test_fmu_path("Plant", GetParam())};
};

// A unit step of drive from rest: speed(t) = K * (1 - exp(-t/T)) at every communication point.
void expect_step_response(LoadedFmu& fmu, double h, int steps) {
  const double gain = 3.0;
  const double time_constant = 0.25;
  std::unique_ptr<Model> plant = Model::instantiate(fmu);
  ASSERT_TRUE(plant->instantiated());
  ASSERT_EQ(plant->set("gain", gain), Status::ok);
  ASSERT_EQ(plant->set("time_constant", time_constant), Status::ok);
  ASSERT_EQ(plant->enter_initialization(), Status::ok);
  ASSERT_EQ(plant->set("drive", 1.0), Status::ok);
  ASSERT_EQ(plant->exit_initialization(), Status::ok) << plant->log_text();
  EXPECT_EQ(plant->get_float("speed"), 0.0);
  for (int k = 0; k < steps; ++k) {
    ASSERT_EQ(plant->do_step(k * h, h), Status::ok) << plant->log_text();
    const double t = (k + 1) * h;
    ASSERT_NEAR(plant->get_float("speed"), gain * (1.0 - std::exp(-t / time_constant)), 1e-12) << "t=" << t;
  }
  EXPECT_NEAR(plant->get_float("speed"), gain, gain * 0.02);  // settled after 4 time constants or more
}

TEST_P(PlantFmu, StepResponseIsTheAnalyticOneForStepsOf10ms) { expect_step_response(fmu_, 0.01, 100); }

TEST_P(PlantFmu, StepResponseIsTheAnalyticOneForStepsOf3ms) { expect_step_response(fmu_, 0.003, 400); }

TEST_P(PlantFmu, StepSizesMayVaryFromStepToStep) {
  std::unique_ptr<Model> plant = Model::instantiate(fmu_);
  ASSERT_EQ(plant->enter_initialization(), Status::ok);
  ASSERT_EQ(plant->set("drive", -0.5), Status::ok);
  ASSERT_EQ(plant->exit_initialization(), Status::ok);
  double t = 0.0;
  const double steps[] = {0.01, 0.003, 0.05, 0.0007, 0.2};
  for (double h : steps) {
    ASSERT_EQ(plant->do_step(t, h), Status::ok);
    t += h;
    // The description's defaults: gain 2, time constant 0.5 s.
    EXPECT_NEAR(plant->get_float("speed"), -0.5 * 2.0 * (1.0 - std::exp(-t / 0.5)), 1e-12) << "t=" << t;
  }
}

TEST_P(PlantFmu, NonPositiveTimeConstantIsRefusedWithItsMessage) {
  for (double time_constant : {0.0, -1.0}) {
    std::unique_ptr<Model> plant = Model::instantiate(fmu_);
    ASSERT_EQ(plant->set("time_constant", time_constant), Status::ok);
    ASSERT_EQ(plant->enter_initialization(), Status::ok);
    EXPECT_EQ(plant->exit_initialization(), Status::error);
    ASSERT_EQ(plant->log().size(), 1u) << plant->log_text();
    EXPECT_EQ(plant->log()[0].status, Status::error);
    EXPECT_EQ(plant->log()[0].category, "logStatusError");
    EXPECT_EQ(plant->log()[0].message,
              "time_constant must be a number of seconds > 0, not " + std::string(time_constant == 0.0 ? "0" : "-1"));
    // Refused initialization leaves the instance in the error state: it does not step.
    EXPECT_EQ(plant->do_step(0.0, 0.01), Status::error);
  }
}

TEST_P(PlantFmu, DoStepBeforeInitializationIsAnError) {
  std::unique_ptr<Model> plant = Model::instantiate(fmu_);
  EXPECT_EQ(plant->do_step(0.0, 0.01), Status::error);
  ASSERT_EQ(plant->log().size(), 1u);
  EXPECT_EQ(plant->log()[0].message, std::string(do_step_name()) + " is not allowed in the instantiated state");
  plant->clear_log();
  ASSERT_EQ(plant->enter_initialization(), Status::ok);
  EXPECT_EQ(plant->do_step(0.0, 0.01), Status::error);
  EXPECT_EQ(plant->log().at(0).message, std::string(do_step_name()) + " is not allowed in initialization mode");
}

TEST_P(PlantFmu, NegativeStepSizeIsAnError) {
  std::unique_ptr<Model> plant = Model::instantiate(fmu_);
  ASSERT_EQ(plant->enter_initialization(), Status::ok);
  ASSERT_EQ(plant->exit_initialization(), Status::ok);
  EXPECT_EQ(plant->do_step(0.0, -0.01), Status::error);
  EXPECT_NE(plant->log().at(0).message.find("step size >= 0"), std::string::npos) << plant->log_text();
}

TEST_P(PlantFmu, FixedParametersAreRefusedAfterInitialization) {
  std::unique_ptr<Model> plant = Model::instantiate(fmu_);
  ASSERT_EQ(plant->enter_initialization(), Status::ok);
  ASSERT_EQ(plant->exit_initialization(), Status::ok);
  EXPECT_EQ(plant->set("gain", 5.0), Status::error);
  EXPECT_EQ(plant->log().at(0).message.substr(plant->log()[0].message.find(':')),
            ": 'gain' is a fixed parameter: set only before initialization ends");
  EXPECT_EQ(plant->set("speed", 5.0), Status::error);  // an output
}

TEST_P(PlantFmu, InstancesInOneProcessKeepTheirOwnState) {
  std::unique_ptr<Model> fast = Model::instantiate(fmu_, "fast");
  std::unique_ptr<Model> slow = Model::instantiate(fmu_, "slow");
  ASSERT_EQ(fast->set("time_constant", 0.1), Status::ok);
  ASSERT_EQ(slow->set("time_constant", 10.0), Status::ok);
  for (Model* plant : {fast.get(), slow.get()}) {
    ASSERT_EQ(plant->enter_initialization(), Status::ok);
    ASSERT_EQ(plant->set("drive", 1.0), Status::ok);
    ASSERT_EQ(plant->exit_initialization(), Status::ok);
  }
  for (int k = 0; k < 10; ++k) {
    ASSERT_EQ(fast->do_step(k * 0.01, 0.01), Status::ok);
    ASSERT_EQ(slow->do_step(k * 0.01, 0.01), Status::ok);
  }
  EXPECT_NEAR(fast->get_float("speed"), 2.0 * (1.0 - std::exp(-0.1 / 0.1)), 1e-12);
  EXPECT_NEAR(slow->get_float("speed"), 2.0 * (1.0 - std::exp(-0.1 / 10.0)), 1e-12);
}

TEST_P(PlantFmu, ResetReturnsToTheStartValues) {
  std::unique_ptr<Model> plant = Model::instantiate(fmu_);
  ASSERT_EQ(plant->set("gain", 4.0), Status::ok);
  ASSERT_EQ(plant->enter_initialization(), Status::ok);
  ASSERT_EQ(plant->set("drive", 1.0), Status::ok);
  ASSERT_EQ(plant->exit_initialization(), Status::ok);
  ASSERT_EQ(plant->do_step(0.0, 0.5), Status::ok);
  ASSERT_GT(plant->get_float("speed"), 0.0);
  ASSERT_EQ(plant->terminate(), Status::ok);
  ASSERT_EQ(plant->reset(), Status::ok);
  ASSERT_EQ(plant->enter_initialization(), Status::ok);
  EXPECT_EQ(plant->get_float("gain"), 2.0);
  EXPECT_EQ(plant->get_float("drive"), 0.0);
  EXPECT_EQ(plant->get_float("speed"), 0.0);
}

TEST_P(PlantFmu, TimeIsTheEndOfTheLastStep) {
  std::unique_ptr<Model> plant = Model::instantiate(fmu_);
  ASSERT_EQ(plant->enter_initialization(2.5), Status::ok);
  EXPECT_EQ(plant->get_float("time"), 2.5);
  ASSERT_EQ(plant->exit_initialization(), Status::ok);
  ASSERT_EQ(plant->do_step(2.5, 0.25), Status::ok);
  EXPECT_EQ(plant->get_float("time"), 2.75);
}

INSTANTIATE_TEST_SUITE_P(Versions, PlantFmu, testing::Values(2, 3), fmi_version_label);

}  // namespace
}  // namespace cosmic::test
