// The closed loop of the test FMUs SpeedController and Plant (tests/fmi_models, docs/fmu.md "Test
// models") computed without any FMU: the reference the tests compare a co-simulation of the two
// with, in one process here and through cosmicd in the runner's closed-loop test.
//
// The coupling is a co-simulation master's with a fixed communication step h and one step of delay
// (Jacobi): at each communication point t_k = k*h both models take the other's last output, then
// both step from t_k to t_k+1. So the controller's step k sees speed_k and the plant's step k
// holds drive_k over the step:
//   e_k = setpoint - speed_k
//   integral_k+1 = integral_k + ki*e_k*h, unless kp*e_k + integral_k is already at or beyond a limit
//     and ki*e_k*h pushes further that way (then integral_k+1 = integral_k)
//   drive_k+1 = clamp(kp*e_k + integral_k+1, drive_min, drive_max)
//   speed_k+1 = K*drive_k + (speed_k - K*drive_k) * exp(-h/T)
// from speed_0 = 0 (the plant at rest), integral_0 = 0 and drive_0 = clamp(kp*setpoint) (the
// controller's output after initialization, its speed input being the plant's initial speed).
//
// Header-only, no I/O; any thread.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace cosmic::test {

struct ClosedLoopParameters {
  // SpeedController's parameters (the description's start values by default).
  double kp = 0.5;
  double ki = 0.2;
  double drive_min = -1.0;
  double drive_max = 1.0;
  // Plant's.
  double gain = 2.0;
  double time_constant = 0.5;
  // The controller's setpoint input, the communication step (s) and how many steps.
  double setpoint = 1.0;
  double step = 0.01;
  std::size_t steps = 0;
};

// The loop's outputs at t = 0, h, ..., steps*h (steps + 1 values each).
struct ClosedLoopTrace {
  std::vector<double> speed;
  std::vector<double> drive;
};

inline ClosedLoopTrace closed_loop_reference(const ClosedLoopParameters& p) {
  const auto limited = [&p](double drive) { return std::min(std::max(drive, p.drive_min), p.drive_max); };
  const double decay = std::exp(-p.step / p.time_constant);
  ClosedLoopTrace trace;
  trace.speed.reserve(p.steps + 1);
  trace.drive.reserve(p.steps + 1);
  double speed = 0.0;
  double integral = 0.0;
  double drive = limited(p.kp * (p.setpoint - speed));
  trace.speed.push_back(speed);
  trace.drive.push_back(drive);
  for (std::size_t k = 0; k < p.steps; ++k) {
    // Both sides advance from the values of t_k: the controller from speed, the plant from drive.
    const double error = p.setpoint - speed;
    const double growth = p.ki * error * p.step;
    const double before = p.kp * error + integral;
    const bool winding_up = (before >= p.drive_max && growth > 0.0) || (before <= p.drive_min && growth < 0.0);
    if (!winding_up) integral += growth;
    const double next_drive = limited(p.kp * error + integral);
    const double held = p.gain * drive;
    speed = held + (speed - held) * decay;
    drive = next_drive;
    trace.speed.push_back(speed);
    trace.drive.push_back(drive);
  }
  return trace;
}

}  // namespace cosmic::test
