/* EveryType (docs/fmu.md "Test models"): an input and an output of every scalar type of the FMI
 * version, each output a fixed function of its input, computed when initialization ends and at
 * each step from the inputs as set before it:
 *   floats (Real; Float32, Float64): twice the input
 *   integers (Integer; Int8 ... UInt64): the input + 1, wrapping at the type's limits
 *     (127 + 1 = -128 for Int8, 2^64 - 1 + 1 = 0 for UInt64)
 *   Boolean: not the input
 *   String: the input with "!" appended
 *   Enumeration (type Gear: park 0, reverse -1, neutral 1, drive 2, in that order): the next item
 *     in declaration order, cyclically (drive is followed by park); a value that is no item fails
 *     the step
 * and a Boolean input `fail`: set at a step, the step logs "step at t=<t> failed: the fail input
 * is set" (category logStatusError) and returns Error.
 *
 * Variables are named after their type and direction: real_in / real_out ... (FMI 2.0),
 * float32_in / float32_out ... uint64_in / uint64_out, boolean_in, string_in, enumeration_in
 * (FMI 3.0); `fail` besides. Each output's value reference is its input's + 1. */
#include <stddef.h>
#include <string.h>

#include "fmu_instance.h"

#define COSMIC_EVERY_INPUT(type, name, vr, kind, start)                                                   \
  {                                                                                                       \
#name "_in", vr, kind, COSMIC_FMU_INPUT, offsetof(every_type_variables, name##_in), { .type = start } \
  }
#define COSMIC_EVERY_OUTPUT(name, vr, kind)                                                                 \
  {                                                                                                         \
#name "_out", vr, kind, COSMIC_FMU_OUTPUT, offsetof(every_type_variables, name##_out), { .integer = 0 } \
  }

#if COSMIC_FMI_VERSION == 2
typedef struct {
  double real_in, real_out;
  int32_t integer_in, integer_out;
  bool boolean_in, boolean_out;
  char *string_in, *string_out;
  int32_t enumeration_in, enumeration_out;
  bool fail;
} every_type_variables;

static const cosmic_fmu_variable kEveryVariables[] = {
    {"time", 0, COSMIC_FMU_FLOAT64, COSMIC_FMU_INDEPENDENT, 0, {.real = 0.0}},
    COSMIC_EVERY_INPUT(real, real, 1, COSMIC_FMU_FLOAT64, 1.5),
    COSMIC_EVERY_OUTPUT(real, 2, COSMIC_FMU_FLOAT64),
    COSMIC_EVERY_INPUT(integer, integer, 3, COSMIC_FMU_INT32, 41),
    COSMIC_EVERY_OUTPUT(integer, 4, COSMIC_FMU_INT32),
    COSMIC_EVERY_INPUT(boolean, boolean, 5, COSMIC_FMU_BOOLEAN, false),
    COSMIC_EVERY_OUTPUT(boolean, 6, COSMIC_FMU_BOOLEAN),
    COSMIC_EVERY_INPUT(string, string, 7, COSMIC_FMU_STRING, "hello"),
    COSMIC_EVERY_OUTPUT(string, 8, COSMIC_FMU_STRING),
    COSMIC_EVERY_INPUT(integer, enumeration, 9, COSMIC_FMU_INT32, 0),
    COSMIC_EVERY_OUTPUT(enumeration, 10, COSMIC_FMU_INT32),
    {"fail", 11, COSMIC_FMU_BOOLEAN, COSMIC_FMU_INPUT, offsetof(every_type_variables, fail), {.boolean = false}},
};
static const uint32_t kEnumerationInput = 9;
static const uint32_t kFailInput = 11;
#define COSMIC_EVERY_TOKEN "{2f7a9c41-0d6e-4b3a-8e15-6c9b2d4f7a02}"
#else
typedef struct {
  float float32_in, float32_out;
  double float64_in, float64_out;
  int8_t int8_in, int8_out;
  uint8_t uint8_in, uint8_out;
  int16_t int16_in, int16_out;
  uint16_t uint16_in, uint16_out;
  int32_t int32_in, int32_out;
  uint32_t uint32_in, uint32_out;
  int64_t int64_in, int64_out;
  uint64_t uint64_in, uint64_out;
  bool boolean_in, boolean_out;
  char *string_in, *string_out;
  int64_t enumeration_in, enumeration_out;
  bool fail;
} every_type_variables;

static const cosmic_fmu_variable kEveryVariables[] = {
    {"time", 0, COSMIC_FMU_FLOAT64, COSMIC_FMU_INDEPENDENT, 0, {.real = 0.0}},
    COSMIC_EVERY_INPUT(real, float32, 1, COSMIC_FMU_FLOAT32, 1.5),
    COSMIC_EVERY_OUTPUT(float32, 2, COSMIC_FMU_FLOAT32),
    COSMIC_EVERY_INPUT(real, float64, 3, COSMIC_FMU_FLOAT64, 2.5),
    COSMIC_EVERY_OUTPUT(float64, 4, COSMIC_FMU_FLOAT64),
    COSMIC_EVERY_INPUT(integer, int8, 5, COSMIC_FMU_INT8, -8),
    COSMIC_EVERY_OUTPUT(int8, 6, COSMIC_FMU_INT8),
    COSMIC_EVERY_INPUT(unsigned_integer, uint8, 7, COSMIC_FMU_UINT8, 8),
    COSMIC_EVERY_OUTPUT(uint8, 8, COSMIC_FMU_UINT8),
    COSMIC_EVERY_INPUT(integer, int16, 9, COSMIC_FMU_INT16, -16),
    COSMIC_EVERY_OUTPUT(int16, 10, COSMIC_FMU_INT16),
    COSMIC_EVERY_INPUT(unsigned_integer, uint16, 11, COSMIC_FMU_UINT16, 16),
    COSMIC_EVERY_OUTPUT(uint16, 12, COSMIC_FMU_UINT16),
    COSMIC_EVERY_INPUT(integer, int32, 13, COSMIC_FMU_INT32, -32),
    COSMIC_EVERY_OUTPUT(int32, 14, COSMIC_FMU_INT32),
    COSMIC_EVERY_INPUT(unsigned_integer, uint32, 15, COSMIC_FMU_UINT32, 32),
    COSMIC_EVERY_OUTPUT(uint32, 16, COSMIC_FMU_UINT32),
    COSMIC_EVERY_INPUT(integer, int64, 17, COSMIC_FMU_INT64, -64),
    COSMIC_EVERY_OUTPUT(int64, 18, COSMIC_FMU_INT64),
    COSMIC_EVERY_INPUT(unsigned_integer, uint64, 19, COSMIC_FMU_UINT64, 64),
    COSMIC_EVERY_OUTPUT(uint64, 20, COSMIC_FMU_UINT64),
    COSMIC_EVERY_INPUT(boolean, boolean, 21, COSMIC_FMU_BOOLEAN, false),
    COSMIC_EVERY_OUTPUT(boolean, 22, COSMIC_FMU_BOOLEAN),
    COSMIC_EVERY_INPUT(string, string, 23, COSMIC_FMU_STRING, "hello"),
    COSMIC_EVERY_OUTPUT(string, 24, COSMIC_FMU_STRING),
    COSMIC_EVERY_INPUT(integer, enumeration, 25, COSMIC_FMU_INT64, 0),
    COSMIC_EVERY_OUTPUT(enumeration, 26, COSMIC_FMU_INT64),
    {"fail", 27, COSMIC_FMU_BOOLEAN, COSMIC_FMU_INPUT, offsetof(every_type_variables, fail), {.boolean = false}},
};
static const uint32_t kEnumerationInput = 25;
static const uint32_t kFailInput = 27;
#define COSMIC_EVERY_TOKEN "{2f7a9c41-0d6e-4b3a-8e15-6c9b2d4f7a03}"
#endif

/* The items of the enumeration type Gear, in declaration order. */
static const int64_t kGearItems[] = {0, -1, 1, 2};
enum { kGearItemCount = sizeof kGearItems / sizeof kGearItems[0] };

static int64_t stored_integer(const void* stored, cosmic_fmu_kind kind) {
  return kind == COSMIC_FMU_INT32 ? *(const int32_t*)stored : *(const int64_t*)stored;
}

static cosmic_fmu_status next_gear(cosmic_fmu_instance* instance, const cosmic_fmu_variable* input, const void* in,
                                   void* out) {
  const int64_t value = stored_integer(in, input->kind);
  for (unsigned i = 0; i < kGearItemCount; ++i) {
    if (kGearItems[i] == value) {
      const int64_t next = kGearItems[(i + 1) % kGearItemCount];
      if (input->kind == COSMIC_FMU_INT32) {
        *(int32_t*)out = (int32_t)next;
      } else {
        *(int64_t*)out = next;
      }
      return COSMIC_FMU_OK;
    }
  }
  return cosmic_fmu_log(instance, COSMIC_FMU_ERROR,
                        "%s is %lld, not an item of Gear (park 0, reverse -1, neutral 1, drive 2)", input->name,
                        (long long)value);
}

/* An integer + 1, computed in the unsigned type of the same width so it wraps at the limits. */
#define COSMIC_EVERY_PLUS_ONE(type, unsigned_type) \
  *(type*)out = (type)(unsigned_type)((unsigned_type) * (const type*)in + 1u)

static cosmic_fmu_status output_of(cosmic_fmu_instance* instance, const cosmic_fmu_variable* input, const void* in,
                                   void* out) {
  if (input->value_reference == kEnumerationInput) {
    return next_gear(instance, input, in, out);
  }
  switch (input->kind) {
    case COSMIC_FMU_FLOAT32:
      *(float*)out = 2.0f * *(const float*)in;
      break;
    case COSMIC_FMU_FLOAT64:
      *(double*)out = 2.0 * *(const double*)in;
      break;
    case COSMIC_FMU_INT8:
      COSMIC_EVERY_PLUS_ONE(int8_t, uint8_t);
      break;
    case COSMIC_FMU_UINT8:
      COSMIC_EVERY_PLUS_ONE(uint8_t, uint8_t);
      break;
    case COSMIC_FMU_INT16:
      COSMIC_EVERY_PLUS_ONE(int16_t, uint16_t);
      break;
    case COSMIC_FMU_UINT16:
      COSMIC_EVERY_PLUS_ONE(uint16_t, uint16_t);
      break;
    case COSMIC_FMU_INT32:
      COSMIC_EVERY_PLUS_ONE(int32_t, uint32_t);
      break;
    case COSMIC_FMU_UINT32:
      COSMIC_EVERY_PLUS_ONE(uint32_t, uint32_t);
      break;
    case COSMIC_FMU_INT64:
      COSMIC_EVERY_PLUS_ONE(int64_t, uint64_t);
      break;
    case COSMIC_FMU_UINT64:
      COSMIC_EVERY_PLUS_ONE(uint64_t, uint64_t);
      break;
    case COSMIC_FMU_BOOLEAN:
      *(bool*)out = !*(const bool*)in;
      break;
    case COSMIC_FMU_STRING:
      return cosmic_fmu_assign_string(instance, out, *(char* const*)in, "!");
  }
  return COSMIC_FMU_OK;
}

/* Every output from its input: the variable whose value reference is the input's + 1. */
static cosmic_fmu_status every_outputs(cosmic_fmu_instance* instance) {
  char* variables = cosmic_fmu_model_variables(instance);
  const cosmic_fmu_model* model = instance->model;
  for (size_t i = 0; i < model->variable_count; ++i) {
    const cosmic_fmu_variable* input = &model->variables[i];
    if (input->role != COSMIC_FMU_INPUT || input->value_reference == kFailInput) {
      continue;
    }
    const cosmic_fmu_variable* output = cosmic_fmu_find_variable(instance, input->value_reference + 1);
    const cosmic_fmu_status status = output_of(instance, input, variables + input->offset, variables + output->offset);
    if (status != COSMIC_FMU_OK) {
      return status;
    }
  }
  return COSMIC_FMU_OK;
}

static cosmic_fmu_status every_parameters(cosmic_fmu_instance* instance) {
  (void)instance; /* no parameters */
  return COSMIC_FMU_OK;
}

static cosmic_fmu_status every_step(cosmic_fmu_instance* instance, double t, double h) {
  (void)h;
  const every_type_variables* every = cosmic_fmu_model_variables(instance);
  if (every->fail) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "step at t=%g failed: the fail input is set", t);
  }
  const cosmic_fmu_status status = every_outputs(instance);
  if (status != COSMIC_FMU_OK) {
    return cosmic_fmu_log(instance, status, "step at t=%g failed: an output cannot be computed", t);
  }
  return COSMIC_FMU_OK;
}

const cosmic_fmu_model cosmic_fmu_this_model = {
    .instantiation_token = COSMIC_EVERY_TOKEN,
    .variables_size = sizeof(every_type_variables),
    .variables = kEveryVariables,
    .variable_count = sizeof kEveryVariables / sizeof kEveryVariables[0],
    .calculate_outputs = every_outputs,
    .check_parameters = every_parameters,
    .do_step = every_step,
};
