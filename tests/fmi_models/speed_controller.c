/* SpeedController (docs/fmu.md "Test models"): the paper's speed controller as a discrete PI
 * controller. Inputs `setpoint` and `speed` (m/s), output `drive` (the actuator command, within
 * [drive_min, drive_max]); tunable parameters `kp` and `ki`, fixed `drive_min` and `drive_max`; the
 * local `integral` is readable for tests.
 *
 * A step from t to t + h, with the inputs as set before it:
 *   e = setpoint - speed
 *   increment = ki * e * h, dropped when kp*e + integral is already at or beyond a limit and the
 *     increment pushes further that way (anti-windup: the integral stops growing while clamped)
 *   integral += increment
 *   drive = clamp(kp*e + integral, drive_min, drive_max)
 * After initialization drive = clamp(kp * (setpoint - speed)) from the values set by then.
 *
 * The same source builds the FMI 2.0 and the FMI 3.0 FMU: Real and Float64 are both double. */
#include <stddef.h>

#include "fmu_instance.h"

typedef struct {
  double setpoint;
  double speed;
  double drive;
  double kp;
  double ki;
  double drive_min;
  double drive_max;
  double integral;
} controller_variables;

#define COSMIC_CONTROLLER_VARIABLE(name, vr, role, start)                                        \
  {                                                                                              \
#name, vr, COSMIC_FMU_FLOAT64, role, offsetof(controller_variables, name), { .real = start } \
  }

static const cosmic_fmu_variable kControllerVariables[] = {
    {"time", 0, COSMIC_FMU_FLOAT64, COSMIC_FMU_INDEPENDENT, 0, {.real = 0.0}},
    COSMIC_CONTROLLER_VARIABLE(setpoint, 1, COSMIC_FMU_INPUT, 0.0),
    COSMIC_CONTROLLER_VARIABLE(speed, 2, COSMIC_FMU_INPUT, 0.0),
    COSMIC_CONTROLLER_VARIABLE(drive, 3, COSMIC_FMU_OUTPUT, 0.0),
    COSMIC_CONTROLLER_VARIABLE(kp, 4, COSMIC_FMU_TUNABLE_PARAMETER, 0.5),
    COSMIC_CONTROLLER_VARIABLE(ki, 5, COSMIC_FMU_TUNABLE_PARAMETER, 0.2),
    COSMIC_CONTROLLER_VARIABLE(drive_min, 6, COSMIC_FMU_FIXED_PARAMETER, -1.0),
    COSMIC_CONTROLLER_VARIABLE(drive_max, 7, COSMIC_FMU_FIXED_PARAMETER, 1.0),
    COSMIC_CONTROLLER_VARIABLE(integral, 8, COSMIC_FMU_LOCAL, 0.0),
};

static double clamp_drive(const controller_variables* controller, double drive) {
  return drive > controller->drive_max ? controller->drive_max
                                       : (drive < controller->drive_min ? controller->drive_min : drive);
}

static cosmic_fmu_status controller_outputs(cosmic_fmu_instance* instance) {
  controller_variables* controller = cosmic_fmu_model_variables(instance);
  controller->drive = clamp_drive(controller, controller->kp * (controller->setpoint - controller->speed));
  return COSMIC_FMU_OK;
}

static cosmic_fmu_status controller_parameters(cosmic_fmu_instance* instance) {
  const controller_variables* controller = cosmic_fmu_model_variables(instance);
  if (!(controller->drive_min <= controller->drive_max)) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "drive_min (%g) must not exceed drive_max (%g)",
                          controller->drive_min, controller->drive_max);
  }
  return COSMIC_FMU_OK;
}

static cosmic_fmu_status controller_step(cosmic_fmu_instance* instance, double t, double h) {
  (void)t;
  controller_variables* controller = cosmic_fmu_model_variables(instance);
  const double error = controller->setpoint - controller->speed;
  const double proportional = controller->kp * error;
  const double increment = controller->ki * error * h;
  const double unclamped = proportional + controller->integral;
  const bool winding_up = (unclamped >= controller->drive_max && increment > 0.0) ||
                          (unclamped <= controller->drive_min && increment < 0.0);
  if (!winding_up) {
    controller->integral += increment;
  }
  controller->drive = clamp_drive(controller, proportional + controller->integral);
  return COSMIC_FMU_OK;
}

const cosmic_fmu_model cosmic_fmu_this_model = {
#if COSMIC_FMI_VERSION == 2
    .instantiation_token = "{9e3b7d52-61a4-4c8f-b0d2-3f5e8a7c1b02}",
#else
    .instantiation_token = "{9e3b7d52-61a4-4c8f-b0d2-3f5e8a7c1b03}",
#endif
    .variables_size = sizeof(controller_variables),
    .variables = kControllerVariables,
    .variable_count = sizeof kControllerVariables / sizeof kControllerVariables[0],
    .calculate_outputs = controller_outputs,
    .check_parameters = controller_parameters,
    .do_step = controller_step,
};
