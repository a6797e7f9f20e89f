/* The FMI 2.0 co-simulation API of the test FMUs over fmu_instance.h (the standard's section 2.1
 * and 4.2; the prototypes from cosmic/fmi2_api.h). Memory comes from the importer's
 * allocateMemory/freeMemory, messages go to its logger. */
#define COSMIC_FMI2_EXPORTS
#include "cosmic/fmi2_api.h"

#include <string.h>

#include "fmu_instance.h"

_Static_assert((int)fmi2Error == (int)COSMIC_FMU_ERROR && (int)fmi2Discard == (int)COSMIC_FMU_DISCARD,
               "fmi2Status and cosmic_fmu_status agree");

/* The logger's message is a printf format: a '%' of the text is written "%%" so it shows as is. */
static void log_to_importer(const cosmic_fmu_instance* instance, cosmic_fmu_status status, const char* category,
                            const char* message) {
  const fmi2CallbackFunctions* functions = instance->host.context;
  char escaped[2048];
  size_t length = 0;
  for (const char* c = message; *c != '\0' && length + 2 < sizeof escaped; ++c) {
    if (*c == '%') {
      escaped[length++] = '%';
    }
    escaped[length++] = *c;
  }
  escaped[length] = '\0';
  functions->logger(functions->componentEnvironment, instance->name, (fmi2Status)status, category, escaped);
}

const char* fmi2GetTypesPlatform(void) { return "default"; }
const char* fmi2GetVersion(void) { return "2.0"; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
  (void)fmuResourceLocation; /* the test models have no resources */
  (void)visible;             /* nor a user interface */
  if (functions == NULL || functions->allocateMemory == NULL || functions->freeMemory == NULL) {
    return NULL;
  }
  const char* refusal = NULL;
  if (instanceName == NULL || instanceName[0] == '\0') {
    refusal = "fmi2Instantiate: the instance name is empty";
  } else if (fmuType != fmi2CoSimulation) {
    refusal = "fmi2Instantiate: this FMU is for co-simulation only";
  } else if (fmuGUID == NULL || strcmp(fmuGUID, cosmic_fmu_this_model.instantiation_token) != 0) {
    refusal = "fmi2Instantiate: the GUID is not the one of this FMU's modelDescription.xml";
  }
  if (refusal != NULL) {
    if (loggingOn && functions->logger != NULL) {
      functions->logger(functions->componentEnvironment, instanceName != NULL ? instanceName : "", fmi2Error,
                        "logStatusError", "%s", refusal);
    }
    return NULL;
  }
  const cosmic_fmu_host host = {
      .allocate = functions->allocateMemory,
      .release = functions->freeMemory,
      .log = functions->logger != NULL ? log_to_importer : NULL,
      .context = functions,
      .environment = functions->componentEnvironment,
  };
  return cosmic_fmu_create(&cosmic_fmu_this_model, &host, instanceName, loggingOn != fmi2False);
}

void fmi2FreeInstance(fmi2Component c) { cosmic_fmu_destroy(c); }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
  if (c == NULL) {
    return fmi2Error;
  }
  return (fmi2Status)cosmic_fmu_set_logging(c, "fmi2SetDebugLogging", loggingOn != fmi2False, nCategories, categories);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
  (void)toleranceDefined; /* the models' steps are exact: no tolerance applies */
  (void)tolerance;
  (void)stopTimeDefined; /* nor does an end time */
  (void)stopTime;
  return c == NULL ? fmi2Error : (fmi2Status)cosmic_fmu_set_start_time(c, "fmi2SetupExperiment", startTime);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  return c == NULL ? fmi2Error : (fmi2Status)cosmic_fmu_enter_initialization(c, "fmi2EnterInitializationMode");
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  return c == NULL ? fmi2Error : (fmi2Status)cosmic_fmu_exit_initialization(c, "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component c) {
  return c == NULL ? fmi2Error : (fmi2Status)cosmic_fmu_terminate(c, "fmi2Terminate");
}

fmi2Status fmi2Reset(fmi2Component c) { return c == NULL ? fmi2Error : (fmi2Status)cosmic_fmu_reset(c); }

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
  (void)noSetFMUStatePriorToCurrentPoint; /* no FMU state is kept for rolling back */
  if (c == NULL) {
    return fmi2Error;
  }
  return (fmi2Status)cosmic_fmu_do_step(c, "fmi2DoStep", currentCommunicationPoint, communicationStepSize);
}

/* How a value crosses the API: stored as `stored`, exchanged as fmi2<T>. */
#define COSMIC_FMI2_GET(T, KIND, STORED, TO_API)                                                        \
  fmi2Status fmi2Get##T(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2##T values[]) { \
    if (c == NULL || cosmic_fmu_begin_get(c, "fmi2Get" #T) >= COSMIC_FMU_ERROR) {                       \
      return fmi2Error;                                                                                 \
    }                                                                                                   \
    for (size_t i = 0; i < nvr; ++i) {                                                                  \
      STORED const* stored = cosmic_fmu_readable(c, "fmi2Get" #T, vr[i], KIND);                         \
      if (stored == NULL) {                                                                             \
        return fmi2Error;                                                                               \
      }                                                                                                 \
      values[i] = TO_API(*stored);                                                                      \
    }                                                                                                   \
    return fmi2OK;                                                                                      \
  }

#define COSMIC_FMI2_SET(T, KIND, STORED, ASSIGN)                                                              \
  fmi2Status fmi2Set##T(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2##T values[]) { \
    if (c == NULL || cosmic_fmu_begin_set(c, "fmi2Set" #T) >= COSMIC_FMU_ERROR) {                             \
      return fmi2Error;                                                                                       \
    }                                                                                                         \
    for (size_t i = 0; i < nvr; ++i) {                                                                        \
      STORED* stored = cosmic_fmu_writable(c, "fmi2Set" #T, vr[i], KIND);                                     \
      if (stored == NULL || ASSIGN(c, stored, values[i]) != COSMIC_FMU_OK) {                                  \
        return fmi2Error;                                                                                     \
      }                                                                                                       \
    }                                                                                                         \
    return fmi2OK;                                                                                            \
  }

#define COSMIC_FMI2_AS_IS(value) (value)
#define COSMIC_FMI2_BOOLEAN(value) ((value) ? fmi2True : fmi2False)

/* A number or a boolean is copied; a string is copied into the instance. */
#define COSMIC_FMI2_COPY(instance, stored, value) (*(stored) = (value), COSMIC_FMU_OK)
#define COSMIC_FMI2_COPY_BOOLEAN(instance, stored, value) (*(stored) = (value) != fmi2False, COSMIC_FMU_OK)

static cosmic_fmu_status assign_string(cosmic_fmu_instance* instance, char** stored, fmi2String value) {
  if (value == NULL) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "fmi2SetString: a value is NULL");
  }
  return cosmic_fmu_assign_string(instance, stored, value, "");
}

COSMIC_FMI2_GET(Real, COSMIC_FMU_FLOAT64, double, COSMIC_FMI2_AS_IS)
COSMIC_FMI2_GET(Integer, COSMIC_FMU_INT32, int32_t, COSMIC_FMI2_AS_IS)
COSMIC_FMI2_GET(Boolean, COSMIC_FMU_BOOLEAN, bool, COSMIC_FMI2_BOOLEAN)
COSMIC_FMI2_GET(String, COSMIC_FMU_STRING, char*, COSMIC_FMI2_AS_IS)
COSMIC_FMI2_SET(Real, COSMIC_FMU_FLOAT64, double, COSMIC_FMI2_COPY)
COSMIC_FMI2_SET(Integer, COSMIC_FMU_INT32, int32_t, COSMIC_FMI2_COPY)
COSMIC_FMI2_SET(Boolean, COSMIC_FMU_BOOLEAN, bool, COSMIC_FMI2_COPY_BOOLEAN)
COSMIC_FMI2_SET(String, COSMIC_FMU_STRING, char*, assign_string)

/* doStep never returns fmi2Pending (it is not asynchronous), so there is no step to cancel and no
 * pending status to ask about; only the last successful time is there to read. */
fmi2Status fmi2CancelStep(fmi2Component c) {
  if (c == NULL) {
    return fmi2Error;
  }
  return (fmi2Status)cosmic_fmu_log(c, COSMIC_FMU_ERROR, "fmi2CancelStep: fmi2DoStep never returns fmi2Pending");
}

static fmi2Status status_not_provided(fmi2Component c, const char* function, fmi2StatusKind kind) {
  if (c == NULL) {
    return fmi2Error;
  }
  return (fmi2Status)cosmic_fmu_log(
      c, COSMIC_FMU_DISCARD,
      "%s: status kind %d is not provided (fmi2DoStep never returns fmi2Pending nor fmi2Discard)", function, (int)kind);
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Status* value) {
  (void)value;
  return status_not_provided(c, "fmi2GetStatus", kind);
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real* value) {
  if (c != NULL && kind == fmi2LastSuccessfulTime && value != NULL) {
    *value = ((cosmic_fmu_instance*)c)->time;
    return fmi2OK;
  }
  return status_not_provided(c, "fmi2GetRealStatus", kind);
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Integer* value) {
  (void)value;
  return status_not_provided(c, "fmi2GetIntegerStatus", kind);
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Boolean* value) {
  (void)value;
  return status_not_provided(c, "fmi2GetBooleanStatus", kind);
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind kind, fmi2String* value) {
  (void)value;
  return status_not_provided(c, "fmi2GetStringStatus", kind);
}
