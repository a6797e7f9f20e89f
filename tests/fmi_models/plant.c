/* Plant (docs/fmu.md "Test models"): a first-order lag, a drive moving a vehicle's mass. Input
 * `drive`, output `speed` (m/s), fixed parameters `gain` K (m/s per unit of drive) and
 * `time_constant` T (s, > 0). Each step holds the drive over the step and solves the lag exactly:
 * speed(t + h) = K*drive + (speed(t) - K*drive) * exp(-h/T), so any step size h gives the same
 * trajectory at the communication points. The speed starts at 0 (at rest).
 *
 * The same source builds the FMI 2.0 and the FMI 3.0 FMU: Real and Float64 are both double. */
#include <math.h>
#include <stddef.h>

#include "fmu_instance.h"

typedef struct {
  double drive;
  double speed;
  double gain;
  double time_constant;
} plant_variables;

static const cosmic_fmu_variable kPlantVariables[] = {
    {"time", 0, COSMIC_FMU_FLOAT64, COSMIC_FMU_INDEPENDENT, 0, {.real = 0.0}},
    {"drive", 1, COSMIC_FMU_FLOAT64, COSMIC_FMU_INPUT, offsetof(plant_variables, drive), {.real = 0.0}},
    {"speed", 2, COSMIC_FMU_FLOAT64, COSMIC_FMU_OUTPUT, offsetof(plant_variables, speed), {.real = 0.0}},
    {"gain", 3, COSMIC_FMU_FLOAT64, COSMIC_FMU_FIXED_PARAMETER, offsetof(plant_variables, gain), {.real = 2.0}},
    {"time_constant",
     4,
     COSMIC_FMU_FLOAT64,
     COSMIC_FMU_FIXED_PARAMETER,
     offsetof(plant_variables, time_constant),
     {.real = 0.5}},
};

/* The speed is the lag's state: at rest until the first step, whatever the inputs. */
static cosmic_fmu_status plant_outputs(cosmic_fmu_instance* instance) {
  (void)instance;
  return COSMIC_FMU_OK;
}

static cosmic_fmu_status plant_parameters(cosmic_fmu_instance* instance) {
  const plant_variables* plant = cosmic_fmu_model_variables(instance);
  if (!(plant->time_constant > 0.0) || !isfinite(plant->time_constant)) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "time_constant must be a number of seconds > 0, not %g",
                          plant->time_constant);
  }
  if (!isfinite(plant->gain)) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "gain must be a finite number, not %g", plant->gain);
  }
  return COSMIC_FMU_OK;
}

static cosmic_fmu_status plant_step(cosmic_fmu_instance* instance, double t, double h) {
  (void)t;
  plant_variables* plant = cosmic_fmu_model_variables(instance);
  const double settled = plant->gain * plant->drive;
  plant->speed = settled + (plant->speed - settled) * exp(-h / plant->time_constant);
  return COSMIC_FMU_OK;
}

const cosmic_fmu_model cosmic_fmu_this_model = {
#if COSMIC_FMI_VERSION == 2
    .instantiation_token = "{5a0c6f1e-38b2-4d61-9f0e-7c2d1b4e8a01}",
#else
    .instantiation_token = "{5a0c6f1e-38b2-4d61-9f0e-7c2d1b4e8a03}",
#endif
    .variables_size = sizeof(plant_variables),
    .variables = kPlantVariables,
    .variable_count = sizeof kPlantVariables / sizeof kPlantVariables[0],
    .calculate_outputs = plant_outputs,
    .check_parameters = plant_parameters,
    .do_step = plant_step,
};
