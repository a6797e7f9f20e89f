// The closed loop of SpeedController and Plant: closed_loop_reference.hpp against hand-computed
// first steps and its settled values, and against the two FMUs co-simulated in one process as the
// reference says (FMI 2.0, FMI 3.0 and one of each), equal to 1e-12.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "closed_loop_reference.hpp"
#include "fmu_driver.hpp"

namespace cosmic::test {
namespace {

TEST(ClosedLoopReference, FirstStepsAreTheHandComputedOnes) {
  ClosedLoopParameters p;  // kp 0.5, ki 0.2, limits -1..1, K 2, T 0.5, setpoint 1, h 0.01
  p.steps = 2;
  const ClosedLoopTrace trace = closed_loop_reference(p);
  ASSERT_EQ(trace.speed.size(), 3u);
  const double decay = std::exp(-0.01 / 0.5);
  EXPECT_EQ(trace.speed[0], 0.0);
  EXPECT_EQ(trace.drive[0], 0.5);  // clamp(0.5 * 1)
  // The plant held drive_0 = 0.5 over the first step; the controller saw speed_0 = 0.
  EXPECT_NEAR(trace.speed[1], 1.0 * (1.0 - decay), 1e-15);
  EXPECT_NEAR(trace.drive[1], 0.5 + 0.2 * 1.0 * 0.01, 1e-15);
  const double integral_2 = 0.002 + 0.2 * (1.0 - trace.speed[1]) * 0.01;
  EXPECT_NEAR(trace.drive[2], 0.5 * (1.0 - trace.speed[1]) + integral_2, 1e-15);
  const double held = 2.0 * trace.drive[1];
  EXPECT_NEAR(trace.speed[2], held + (trace.speed[1] - held) * decay, 1e-15);
}

TEST(ClosedLoopReference, SettlesAtTheSetpoint) {
  ClosedLoopParameters p;
  p.steps = 10000;  // 100 s: 20 times the loop's slowest time constant (about 5 s)
  const ClosedLoopTrace trace = closed_loop_reference(p);
  EXPECT_NEAR(trace.speed.back(), 1.0, 1e-6);
  EXPECT_NEAR(trace.drive.back(), 0.5, 1e-6);  // setpoint / K
}

TEST(ClosedLoopReference, AnUnreachableSetpointLeavesTheDriveAtItsLimit) {
  ClosedLoopParameters p;
  p.setpoint = 3.0;  // K * drive_max = 2 m/s at most
  p.steps = 3000;
  const ClosedLoopTrace trace = closed_loop_reference(p);
  EXPECT_NEAR(trace.speed.back(), 2.0, 1e-6);
  EXPECT_EQ(trace.drive.back(), 1.0);
}

struct LoopCase {
  int controller_version;
  int plant_version;
};

std::string loop_label(const testing::TestParamInfo<LoopCase>& info) {
  return "ControllerFmi" + std::to_string(info.param.controller_version) + "PlantFmi" +
         std::to_string(info.param.plant_version);
}

class ClosedLoopOfTheFmus : public testing::TestWithParam<LoopCase> {
 protected:
  // Co-simulates the two FMUs as closed_loop_reference.hpp describes and compares every
  // communication point with it.
  void expect_reference(const ClosedLoopParameters& p) {
    LoadedFmu controller_fmu(test_fmu_path("SpeedController", GetParam().controller_version));
    LoadedFmu plant_fmu(test_fmu_path("Plant", GetParam().plant_version));
    ASSERT_TRUE(controller_fmu.ok()) << controller_fmu.error();
    ASSERT_TRUE(plant_fmu.ok()) << plant_fmu.error();
    std::unique_ptr<Model> controller = Model::instantiate(controller_fmu, "controller");
    std::unique_ptr<Model> plant = Model::instantiate(plant_fmu, "plant");
    ASSERT_EQ(controller->set("kp", p.kp), Status::ok);
    ASSERT_EQ(controller->set("ki", p.ki), Status::ok);
    ASSERT_EQ(controller->set("drive_min", p.drive_min), Status::ok);
    ASSERT_EQ(controller->set("drive_max", p.drive_max), Status::ok);
    ASSERT_EQ(plant->set("gain", p.gain), Status::ok);
    ASSERT_EQ(plant->set("time_constant", p.time_constant), Status::ok);
    ASSERT_EQ(controller->enter_initialization(), Status::ok);
    ASSERT_EQ(plant->enter_initialization(), Status::ok);
    ASSERT_EQ(controller->set("setpoint", p.setpoint), Status::ok);
    ASSERT_EQ(controller->set("speed", plant->get_float("speed")), Status::ok);
    ASSERT_EQ(plant->set("drive", controller->get_float("drive")), Status::ok);
    ASSERT_EQ(controller->exit_initialization(), Status::ok) << controller->log_text();
    ASSERT_EQ(plant->exit_initialization(), Status::ok) << plant->log_text();

    const ClosedLoopTrace reference = closed_loop_reference(p);
    double speed = plant->get_float("speed");
    double drive = controller->get_float("drive");
    for (std::size_t k = 0;; ++k) {
      ASSERT_NEAR(speed, reference.speed[k], 1e-12) << "k=" << k;
      ASSERT_NEAR(drive, reference.drive[k], 1e-12) << "k=" << k;
      if (k == p.steps) break;
      // Jacobi: both take the other's output at t_k, then both step.
      ASSERT_EQ(controller->set("speed", speed), Status::ok);
      ASSERT_EQ(plant->set("drive", drive), Status::ok);
      const double t = static_cast<double>(k) * p.step;
      ASSERT_EQ(controller->do_step(t, p.step), Status::ok) << controller->log_text();
      ASSERT_EQ(plant->do_step(t, p.step), Status::ok) << plant->log_text();
      speed = plant->get_float("speed");
      drive = controller->get_float("drive");
    }
  }
};

TEST_P(ClosedLoopOfTheFmus, FollowsTheReferenceWithTheDescriptionsParameters) {
  ClosedLoopParameters p;
  p.steps = 500;
  expect_reference(p);
}

TEST_P(ClosedLoopOfTheFmus, FollowsTheReferenceThroughSaturation) {
  ClosedLoopParameters p;
  p.kp = 0.8;
  p.ki = 2.0;
  p.drive_min = -0.5;
  p.drive_max = 1.2;
  p.gain = 1.5;
  p.time_constant = 0.3;
  p.setpoint = 1.7;  // clamp(0.8 * 1.7) = 1.2 at first: the drive starts clamped
  p.step = 0.003;
  p.steps = 1000;
  const ClosedLoopTrace reference = closed_loop_reference(p);
  ASSERT_EQ(reference.drive[1], 1.2);
  ASSERT_LT(reference.drive.back(), 1.2);
  expect_reference(p);
}

INSTANTIATE_TEST_SUITE_P(Versions, ClosedLoopOfTheFmus,
                         testing::Values(LoopCase{2, 2}, LoopCase{3, 3}, LoopCase{3, 2}, LoopCase{2, 3}), loop_label);

}  // namespace
}  // namespace cosmic::test
