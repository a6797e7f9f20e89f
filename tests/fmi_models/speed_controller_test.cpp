// The SpeedController test FMU (speed_controller.c), FMI 2.0 and 3.0 alike: its drive for a known
// sequence of measured speeds is the hand-computed one, the clamp stops the integral (anti-windup),
// the tunable gains change between steps and the limits are checked.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "fmu_driver.hpp"

namespace cosmic::test {
namespace {

class SpeedControllerFmu : public testing::TestWithParam<int> {
 protected:
  void SetUp() override { ASSERT_TRUE(fmu_.ok()) << fmu_.error(); }

  // kp 0.5, ki 10 and steps of 0.1 s: each step adds the error itself to the integral.
  std::unique_ptr<Model> initialized(double setpoint, double drive_min, double drive_max) {
    std::unique_ptr<Model> controller = Model::instantiate(fmu_);
    EXPECT_TRUE(controller->instantiated());
    EXPECT_EQ(controller->set("kp", 0.5), Status::ok);
    EXPECT_EQ(controller->set("ki", 10.0), Status::ok);
    EXPECT_EQ(controller->set("drive_min", drive_min), Status::ok);
    EXPECT_EQ(controller->set("drive_max", drive_max), Status::ok);
    EXPECT_EQ(controller->enter_initialization(), Status::ok);
    EXPECT_EQ(controller->set("setpoint", setpoint), Status::ok);
    EXPECT_EQ(controller->exit_initialization(), Status::ok) << controller->log_text();
    return controller;
  }

  LoadedFmu fmu_{test_fmu_path("SpeedController", GetParam())};
};

constexpr double kStep = 0.1;

TEST_P(SpeedControllerFmu, DriveForAKnownErrorSequenceIsTheHandComputedOne) {
  std::unique_ptr<Model> controller = initialized(1.0, -1.0, 1.5);
  // After initialization: clamp(kp * (1 - 0)).
  EXPECT_NEAR(controller->get_float("drive"), 0.5, 1e-12);
  // speed -> error e; integral += e; drive = 0.5 e + integral.
  struct Expected {
    double speed, integral, drive;
  };
  const Expected sequence[] = {
      {0.8, 0.2, 0.1 + 0.2},   // e 0.2
      {0.5, 0.7, 0.25 + 0.7},  // e 0.5
      {0.9, 0.8, 0.05 + 0.8},  // e 0.1
      {1.2, 0.6, -0.1 + 0.6},  // e -0.2
      {1.0, 0.6, 0.0 + 0.6},   // e 0
      {3.0, -1.4, -1.0},       // e -2: -1 + 0.6 is within the limits; -1 - 1.4 is clamped
      {3.0, -1.4, -1.0},       // e -2: -1 - 1.4 is below drive_min: the integral holds
  };
  for (std::size_t k = 0; k < std::size(sequence); ++k) {
    ASSERT_EQ(controller->set("speed", sequence[k].speed), Status::ok);
    ASSERT_EQ(controller->do_step(k * kStep, kStep), Status::ok) << controller->log_text();
    EXPECT_NEAR(controller->get_float("integral"), sequence[k].integral, 1e-12) << "step " << k;
    EXPECT_NEAR(controller->get_float("drive"), sequence[k].drive, 1e-12) << "step " << k;
  }
}

TEST_P(SpeedControllerFmu, TheClampStopsTheIntegral) {
  std::unique_ptr<Model> controller = initialized(10.0, -1.0, 1.0);
  EXPECT_EQ(controller->get_float("drive"), 1.0);  // clamp(0.5 * 10)
  // Clamped high with a positive error: the integral does not grow.
  for (int k = 0; k < 5; ++k) {
    ASSERT_EQ(controller->set("speed", 0.0), Status::ok);
    ASSERT_EQ(controller->do_step(k * kStep, kStep), Status::ok);
    EXPECT_EQ(controller->get_float("drive"), 1.0);
    EXPECT_EQ(controller->get_float("integral"), 0.0) << "step " << k;
  }
  // The error reverses: the drive answers at once (no wound-up integral to work off): e = -0.5,
  // integral -0.5, drive -0.25 - 0.5.
  ASSERT_EQ(controller->set("speed", 10.5), Status::ok);
  ASSERT_EQ(controller->do_step(5 * kStep, kStep), Status::ok);
  EXPECT_NEAR(controller->get_float("integral"), -0.5, 1e-12);
  EXPECT_NEAR(controller->get_float("drive"), -0.75, 1e-12);
  // Clamped low with a negative error: the integral stays where it is.
  for (int k = 6; k < 9; ++k) {
    ASSERT_EQ(controller->set("speed", 30.0), Status::ok);
    ASSERT_EQ(controller->do_step(k * kStep, kStep), Status::ok);
    EXPECT_EQ(controller->get_float("drive"), -1.0);
    EXPECT_NEAR(controller->get_float("integral"), -0.5, 1e-12) << "step " << k;
  }
}

TEST_P(SpeedControllerFmu, TheIntegralGrowsUntilTheDriveIsClampedThenHolds) {
  std::unique_ptr<Model> controller = initialized(1.0, -1.0, 1.0);
  // e 0.5: 0.25 + 0 is within the limits, the integral grows; again (0.25 + 0.5): it grows to 1 and
  // the drive is clamped; now 0.25 + 1 and then 0.05 + 1 are at the limit: it holds; e -0.2 pulls
  // the drive back below the limit at once.
  const double speeds[] = {0.5, 0.5, 0.5, 0.9, 1.2};
  const double integrals[] = {0.5, 1.0, 1.0, 1.0, 0.8};
  const double drives[] = {0.75, 1.0, 1.0, 1.0, 0.7};
  for (std::size_t k = 0; k < std::size(speeds); ++k) {
    ASSERT_EQ(controller->set("speed", speeds[k]), Status::ok);
    ASSERT_EQ(controller->do_step(k * kStep, kStep), Status::ok);
    EXPECT_NEAR(controller->get_float("integral"), integrals[k], 1e-12) << "step " << k;
    EXPECT_NEAR(controller->get_float("drive"), drives[k], 1e-12) << "step " << k;
  }
}

TEST_P(SpeedControllerFmu, TunableGainsChangeBetweenSteps) {
  std::unique_ptr<Model> controller = initialized(1.0, -10.0, 10.0);
  ASSERT_EQ(controller->set("speed", 0.0), Status::ok);
  ASSERT_EQ(controller->set("kp", 2.0), Status::ok);
  ASSERT_EQ(controller->set("ki", 0.0), Status::ok);
  ASSERT_EQ(controller->do_step(0.0, kStep), Status::ok);
  EXPECT_NEAR(controller->get_float("drive"), 2.0, 1e-12);
  EXPECT_EQ(controller->set("drive_max", 3.0), Status::error);  // fixed
  EXPECT_EQ(controller->set("drive", 3.0), Status::error);      // an output
  EXPECT_EQ(controller->set("integral", 3.0), Status::error);   // computed
}

TEST_P(SpeedControllerFmu, LimitsTheWrongWayRoundAreRefused) {
  std::unique_ptr<Model> controller = Model::instantiate(fmu_);
  ASSERT_EQ(controller->set("drive_min", 2.0), Status::ok);
  ASSERT_EQ(controller->set("drive_max", 1.0), Status::ok);
  ASSERT_EQ(controller->enter_initialization(), Status::ok);
  EXPECT_EQ(controller->exit_initialization(), Status::error);
  ASSERT_EQ(controller->log().size(), 1u);
  EXPECT_EQ(controller->log()[0].message, "drive_min (2) must not exceed drive_max (1)");
}

TEST_P(SpeedControllerFmu, DriveFollowsTheInputsDuringInitialization) {
  std::unique_ptr<Model> controller = Model::instantiate(fmu_);
  ASSERT_EQ(controller->enter_initialization(), Status::ok);
  ASSERT_EQ(controller->set("setpoint", 1.0), Status::ok);
  ASSERT_EQ(controller->set("speed", 0.4), Status::ok);
  EXPECT_NEAR(controller->get_float("drive"), 0.5 * 0.6, 1e-12);  // kp's start value 0.5
  ASSERT_EQ(controller->set("speed", -10.0), Status::ok);
  EXPECT_EQ(controller->get_float("drive"), 1.0);  // drive_max's start value
}

TEST_P(SpeedControllerFmu, ReadingBeforeInitializationIsAnError) {
  std::unique_ptr<Model> controller = Model::instantiate(fmu_);
  Value drive;
  EXPECT_EQ(controller->get(*fmu_.variable("drive"), drive), Status::error);
  EXPECT_NE(controller->log().at(0).message.find("is not allowed in the instantiated state"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Versions, SpeedControllerFmu, testing::Values(2, 3), fmi_version_label);

}  // namespace
}  // namespace cosmic::test
