/* One test FMU instance, whatever the FMI version and the model: fmu_instance.h. */
#include "fmu_instance.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* The log categories, indexed by status (OK has none: the models log only problems). */
static const char* const kCategories[] = {NULL, "logStatusWarning", "logStatusDiscard", "logStatusError",
                                          "logStatusFatal"};
enum { kCategoryCount = sizeof kCategories / sizeof kCategories[0] };
static const unsigned kAllCategories = (1u << kCategoryCount) - 1u;

static const char* state_name(cosmic_fmu_state state) {
  switch (state) {
    case COSMIC_FMU_INSTANTIATED:
      return "the instantiated state";
    case COSMIC_FMU_INITIALIZATION_MODE:
      return "initialization mode";
    case COSMIC_FMU_STEP_MODE:
      return "step mode";
    case COSMIC_FMU_TERMINATED:
      return "the terminated state";
    case COSMIC_FMU_FAILED:
      return "the error state (an earlier call returned Error)";
  }
  return "an unknown state";
}

cosmic_fmu_status cosmic_fmu_log(const cosmic_fmu_instance* instance, cosmic_fmu_status status, const char* format,
                                 ...) {
  const unsigned index = (unsigned)status;
  if (index >= kCategoryCount || kCategories[index] == NULL || !(instance->logged_categories & (1u << index)) ||
      instance->host.log == NULL) {
    return status;
  }
  char message[1024];
  va_list arguments;
  va_start(arguments, format);
  vsnprintf(message, sizeof message, format, arguments);
  va_end(arguments);
  instance->host.log(instance, status, kCategories[index], message);
  return status;
}

static char* copy_text(const cosmic_fmu_instance* instance, const char* prefix, const char* suffix) {
  const size_t prefix_length = strlen(prefix);
  const size_t suffix_length = strlen(suffix);
  char* text = instance->host.allocate(prefix_length + suffix_length + 1, 1);
  if (text != NULL) {
    memcpy(text, prefix, prefix_length);
    memcpy(text + prefix_length, suffix, suffix_length + 1);
  }
  return text;
}

void* cosmic_fmu_model_variables(cosmic_fmu_instance* instance) { return instance->variables; }

static void* storage_of(const cosmic_fmu_instance* instance, const cosmic_fmu_variable* variable) {
  return (char*)instance->variables + variable->offset;
}

cosmic_fmu_status cosmic_fmu_assign_string(cosmic_fmu_instance* instance, char** slot, const char* prefix,
                                           const char* suffix) {
  char* text = copy_text(instance, prefix, suffix);
  if (text == NULL) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "out of memory for a string of %zu bytes",
                          strlen(prefix) + strlen(suffix) + 1);
  }
  instance->host.release(*slot);
  *slot = text;
  return COSMIC_FMU_OK;
}

static void release_strings(cosmic_fmu_instance* instance) {
  for (size_t i = 0; i < instance->model->variable_count; ++i) {
    const cosmic_fmu_variable* variable = &instance->model->variables[i];
    if (variable->kind == COSMIC_FMU_STRING && variable->role != COSMIC_FMU_INDEPENDENT) {
      char** slot = storage_of(instance, variable);
      instance->host.release(*slot);
      *slot = NULL;
    }
  }
}

/* Every variable to its start value (those without one to zero; strings to ""). */
static cosmic_fmu_status apply_start_values(cosmic_fmu_instance* instance) {
  release_strings(instance);
  memset(instance->variables, 0, instance->model->variables_size);
  for (size_t i = 0; i < instance->model->variable_count; ++i) {
    const cosmic_fmu_variable* variable = &instance->model->variables[i];
    if (variable->role == COSMIC_FMU_INDEPENDENT) {
      continue;
    }
    void* storage = storage_of(instance, variable);
    const cosmic_fmu_start start = variable->start;
    switch (variable->kind) {
      case COSMIC_FMU_FLOAT32:
        *(float*)storage = (float)start.real;
        break;
      case COSMIC_FMU_FLOAT64:
        *(double*)storage = start.real;
        break;
      case COSMIC_FMU_INT8:
        *(int8_t*)storage = (int8_t)start.integer;
        break;
      case COSMIC_FMU_UINT8:
        *(uint8_t*)storage = (uint8_t)start.unsigned_integer;
        break;
      case COSMIC_FMU_INT16:
        *(int16_t*)storage = (int16_t)start.integer;
        break;
      case COSMIC_FMU_UINT16:
        *(uint16_t*)storage = (uint16_t)start.unsigned_integer;
        break;
      case COSMIC_FMU_INT32:
        *(int32_t*)storage = (int32_t)start.integer;
        break;
      case COSMIC_FMU_UINT32:
        *(uint32_t*)storage = (uint32_t)start.unsigned_integer;
        break;
      case COSMIC_FMU_INT64:
        *(int64_t*)storage = start.integer;
        break;
      case COSMIC_FMU_UINT64:
        *(uint64_t*)storage = start.unsigned_integer;
        break;
      case COSMIC_FMU_BOOLEAN:
        *(bool*)storage = start.boolean;
        break;
      case COSMIC_FMU_STRING:
        if (cosmic_fmu_assign_string(instance, storage, start.string != NULL ? start.string : "", "") !=
            COSMIC_FMU_OK) {
          return COSMIC_FMU_ERROR;
        }
        break;
    }
  }
  return COSMIC_FMU_OK;
}

cosmic_fmu_instance* cosmic_fmu_create(const cosmic_fmu_model* model, const cosmic_fmu_host* host, const char* name,
                                       bool logging_on) {
  cosmic_fmu_instance* instance = host->allocate(1, sizeof *instance);
  if (instance == NULL) {
    return NULL;
  }
  instance->host = *host;
  instance->model = model;
  instance->logged_categories = logging_on ? kAllCategories : 0u;
  instance->state = COSMIC_FMU_INSTANTIATED;
  instance->name = copy_text(instance, name, "");
  instance->variables = host->allocate(1, model->variables_size);
  if (instance->name == NULL || instance->variables == NULL || apply_start_values(instance) != COSMIC_FMU_OK) {
    cosmic_fmu_destroy(instance);
    return NULL;
  }
  return instance;
}

void cosmic_fmu_destroy(cosmic_fmu_instance* instance) {
  if (instance == NULL) {
    return;
  }
  if (instance->variables != NULL) {
    release_strings(instance);
    instance->host.release(instance->variables);
  }
  instance->host.release(instance->name);
  instance->host.release(instance);
}

cosmic_fmu_status cosmic_fmu_reset(cosmic_fmu_instance* instance) {
  instance->state = COSMIC_FMU_INSTANTIATED;
  instance->time = 0.0;
  if (apply_start_values(instance) != COSMIC_FMU_OK) {
    instance->state = COSMIC_FMU_FAILED;
    return COSMIC_FMU_ERROR;
  }
  return COSMIC_FMU_OK;
}

bool cosmic_fmu_allowed(cosmic_fmu_instance* instance, const char* function, unsigned allowed_states) {
  if (allowed_states & COSMIC_FMU_IN(instance->state)) {
    return true;
  }
  cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "%s is not allowed in %s", function, state_name(instance->state));
  return false;
}

cosmic_fmu_status cosmic_fmu_set_start_time(cosmic_fmu_instance* instance, const char* function, double start_time) {
  if (!cosmic_fmu_allowed(instance, function, COSMIC_FMU_IN(COSMIC_FMU_INSTANTIATED))) {
    return COSMIC_FMU_ERROR;
  }
  if (!isfinite(start_time)) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "%s: the start time %g is not a finite number", function,
                          start_time);
  }
  instance->time = start_time;
  return COSMIC_FMU_OK;
}

cosmic_fmu_status cosmic_fmu_enter_initialization(cosmic_fmu_instance* instance, const char* function) {
  if (!cosmic_fmu_allowed(instance, function, COSMIC_FMU_IN(COSMIC_FMU_INSTANTIATED))) {
    return COSMIC_FMU_ERROR;
  }
  instance->state = COSMIC_FMU_INITIALIZATION_MODE;
  return COSMIC_FMU_OK;
}

/* A model's Error moves the instance to the error state (the standard's: only reads, terminate,
 * reset and free follow). */
static cosmic_fmu_status settle(cosmic_fmu_instance* instance, cosmic_fmu_status status) {
  if (status >= COSMIC_FMU_ERROR) {
    instance->state = COSMIC_FMU_FAILED;
  }
  return status;
}

cosmic_fmu_status cosmic_fmu_exit_initialization(cosmic_fmu_instance* instance, const char* function) {
  if (!cosmic_fmu_allowed(instance, function, COSMIC_FMU_IN(COSMIC_FMU_INITIALIZATION_MODE))) {
    return COSMIC_FMU_ERROR;
  }
  cosmic_fmu_status status = instance->model->check_parameters(instance);
  if (status < COSMIC_FMU_ERROR) {
    status = instance->model->calculate_outputs(instance);
  }
  if (status < COSMIC_FMU_ERROR) {
    instance->state = COSMIC_FMU_STEP_MODE;
  }
  return settle(instance, status);
}

cosmic_fmu_status cosmic_fmu_do_step(cosmic_fmu_instance* instance, const char* function, double t, double h) {
  if (!cosmic_fmu_allowed(instance, function, COSMIC_FMU_IN(COSMIC_FMU_STEP_MODE))) {
    return COSMIC_FMU_ERROR;
  }
  if (!isfinite(t) || !isfinite(h) || h < 0.0) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR,
                          "%s: the step from t=%g by %g is not a finite time and a step size >= 0", function, t, h);
  }
  const cosmic_fmu_status status = settle(instance, instance->model->do_step(instance, t, h));
  if (status < COSMIC_FMU_ERROR) {
    instance->time = t + h;
  }
  return status;
}

cosmic_fmu_status cosmic_fmu_terminate(cosmic_fmu_instance* instance, const char* function) {
  if (!cosmic_fmu_allowed(instance, function, COSMIC_FMU_IN(COSMIC_FMU_STEP_MODE) | COSMIC_FMU_IN(COSMIC_FMU_FAILED))) {
    return COSMIC_FMU_ERROR;
  }
  instance->state = COSMIC_FMU_TERMINATED;
  return COSMIC_FMU_OK;
}

const cosmic_fmu_variable* cosmic_fmu_find_variable(const cosmic_fmu_instance* instance, uint32_t value_reference) {
  for (size_t i = 0; i < instance->model->variable_count; ++i) {
    if (instance->model->variables[i].value_reference == value_reference) {
      return &instance->model->variables[i];
    }
  }
  return NULL;
}

cosmic_fmu_status cosmic_fmu_begin_get(cosmic_fmu_instance* instance, const char* function) {
  const unsigned readable = COSMIC_FMU_IN(COSMIC_FMU_INITIALIZATION_MODE) | COSMIC_FMU_IN(COSMIC_FMU_STEP_MODE) |
                            COSMIC_FMU_IN(COSMIC_FMU_TERMINATED) | COSMIC_FMU_IN(COSMIC_FMU_FAILED);
  if (!cosmic_fmu_allowed(instance, function, readable)) {
    return COSMIC_FMU_ERROR;
  }
  /* During initialization the outputs follow the inputs and parameters set so far. */
  if (instance->state == COSMIC_FMU_INITIALIZATION_MODE) {
    return instance->model->calculate_outputs(instance);
  }
  return COSMIC_FMU_OK;
}

cosmic_fmu_status cosmic_fmu_begin_set(cosmic_fmu_instance* instance, const char* function) {
  const unsigned writable = COSMIC_FMU_IN(COSMIC_FMU_INSTANTIATED) | COSMIC_FMU_IN(COSMIC_FMU_INITIALIZATION_MODE) |
                            COSMIC_FMU_IN(COSMIC_FMU_STEP_MODE);
  return cosmic_fmu_allowed(instance, function, writable) ? COSMIC_FMU_OK : COSMIC_FMU_ERROR;
}

static const cosmic_fmu_variable* find_of_kind(cosmic_fmu_instance* instance, const char* function,
                                               uint32_t value_reference, cosmic_fmu_kind kind) {
  const cosmic_fmu_variable* variable = cosmic_fmu_find_variable(instance, value_reference);
  if (variable == NULL) {
    cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "%s: no variable has value reference %u", function, value_reference);
    return NULL;
  }
  if (variable->kind != kind) {
    cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "%s: variable '%s' (value reference %u) is of another type", function,
                   variable->name, value_reference);
    return NULL;
  }
  return variable;
}

const void* cosmic_fmu_readable(cosmic_fmu_instance* instance, const char* function, uint32_t value_reference,
                                cosmic_fmu_kind kind) {
  const cosmic_fmu_variable* variable = find_of_kind(instance, function, value_reference, kind);
  if (variable == NULL) {
    return NULL;
  }
  return variable->role == COSMIC_FMU_INDEPENDENT ? (const void*)&instance->time : storage_of(instance, variable);
}

void* cosmic_fmu_writable(cosmic_fmu_instance* instance, const char* function, uint32_t value_reference,
                          cosmic_fmu_kind kind) {
  const cosmic_fmu_variable* variable = find_of_kind(instance, function, value_reference, kind);
  if (variable == NULL) {
    return NULL;
  }
  const bool before_steps = instance->state != COSMIC_FMU_STEP_MODE;
  switch (variable->role) {
    case COSMIC_FMU_INPUT:
    case COSMIC_FMU_TUNABLE_PARAMETER:
      return storage_of(instance, variable);
    case COSMIC_FMU_FIXED_PARAMETER:
      if (before_steps) {
        return storage_of(instance, variable);
      }
      cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "%s: '%s' is a fixed parameter: set only before initialization ends",
                     function, variable->name);
      return NULL;
    case COSMIC_FMU_INDEPENDENT:
    case COSMIC_FMU_OUTPUT:
    case COSMIC_FMU_LOCAL:
      break;
  }
  cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "%s: '%s' is computed by the model and cannot be set", function,
                 variable->name);
  return NULL;
}

cosmic_fmu_status cosmic_fmu_set_logging(cosmic_fmu_instance* instance, const char* function, bool on,
                                         size_t category_count, const char* const categories[]) {
  unsigned chosen = category_count == 0 ? kAllCategories : 0u;
  for (size_t i = 0; i < category_count; ++i) {
    unsigned found = 0;
    for (unsigned index = 0; index < kCategoryCount; ++index) {
      if (kCategories[index] != NULL && categories[i] != NULL && strcmp(kCategories[index], categories[i]) == 0) {
        found = 1u << index;
      }
    }
    if (found == 0) {
      return cosmic_fmu_log(instance, COSMIC_FMU_ERROR,
                            "%s: unknown log category '%s' (logStatusWarning, logStatusDiscard, logStatusError, "
                            "logStatusFatal)",
                            function, categories[i] != NULL ? categories[i] : "(null)");
    }
    chosen |= found;
  }
  instance->logged_categories = on ? (instance->logged_categories | chosen) : (instance->logged_categories & ~chosen);
  return COSMIC_FMU_OK;
}
