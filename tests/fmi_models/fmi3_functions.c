/* The FMI 3.0 co-simulation API of the test FMUs over fmu_instance.h (the standard's sections 2.2
 * and 4.2; the prototypes from cosmic/fmi3_api.h). No event mode, no early return, no intermediate
 * update: an instance goes from initialization straight to step mode. Memory comes from calloc,
 * messages go to the importer's logMessage. */
#define COSMIC_FMI3_EXPORTS
#include "cosmic/fmi3_api.h"

#include <stdlib.h>
#include <string.h>

#include "fmu_instance.h"

_Static_assert((int)fmi3Error == (int)COSMIC_FMU_ERROR && (int)fmi3Discard == (int)COSMIC_FMU_DISCARD,
               "fmi3Status and cosmic_fmu_status agree");

/* The importer's logMessage, in memory of its own (host.context): a function pointer does not
 * convert to void*. Freed with the instance. */
typedef struct {
  fmi3LogMessageCallback log_message;
} importer_callbacks;

static void log_to_importer(const cosmic_fmu_instance* instance, cosmic_fmu_status status, const char* category,
                            const char* message) {
  const importer_callbacks* callbacks = instance->host.context;
  callbacks->log_message(instance->host.environment, (fmi3Status)status, category, message);
}

static void release(void* memory) { free(memory); }

const char* fmi3GetVersion(void) { return "3.0"; }

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
  (void)resourcePath;                  /* the test models have no resources */
  (void)visible;                       /* nor a user interface */
  (void)earlyReturnAllowed;            /* a step never returns early */
  (void)requiredIntermediateVariables; /* refused below when there are any */
  (void)intermediateUpdate;            /* never called: providesIntermediateUpdate is false */
  const char* refusal = NULL;
  if (instanceName == NULL || instanceName[0] == '\0') {
    refusal = "fmi3InstantiateCoSimulation: the instance name is empty";
  } else if (instantiationToken == NULL || strcmp(instantiationToken, cosmic_fmu_this_model.instantiation_token) != 0) {
    refusal = "fmi3InstantiateCoSimulation: the instantiation token is not the one of this FMU's modelDescription.xml";
  } else if (eventModeUsed) {
    refusal = "fmi3InstantiateCoSimulation: this FMU has no event mode (hasEventMode is false)";
  } else if (nRequiredIntermediateVariables != 0) {
    refusal = "fmi3InstantiateCoSimulation: this FMU provides no intermediate update";
  }
  if (refusal != NULL) {
    if (loggingOn && logMessage != NULL) {
      logMessage(instanceEnvironment, fmi3Error, "logStatusError", refusal);
    }
    return NULL;
  }
  importer_callbacks* callbacks = calloc(1, sizeof *callbacks);
  if (callbacks == NULL) {
    return NULL;
  }
  callbacks->log_message = logMessage;
  const cosmic_fmu_host host = {
      .allocate = calloc,
      .release = release,
      .log = logMessage != NULL ? log_to_importer : NULL,
      .context = callbacks,
      .environment = instanceEnvironment,
  };
  cosmic_fmu_instance* instance = cosmic_fmu_create(&cosmic_fmu_this_model, &host, instanceName, loggingOn);
  if (instance == NULL) {
    free(callbacks);
  }
  return instance;
}

void fmi3FreeInstance(fmi3Instance instance) {
  if (instance != NULL) {
    void* callbacks = (void*)((cosmic_fmu_instance*)instance)->host.context;
    cosmic_fmu_destroy(instance);
    free(callbacks);
  }
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
  if (instance == NULL) {
    return fmi3Error;
  }
  return (fmi3Status)cosmic_fmu_set_logging(instance, "fmi3SetDebugLogging", loggingOn, nCategories, categories);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
  (void)toleranceDefined; /* the models' steps are exact: no tolerance applies */
  (void)tolerance;
  (void)stopTimeDefined; /* nor does an end time */
  (void)stopTime;
  if (instance == NULL) {
    return fmi3Error;
  }
  const cosmic_fmu_status status = cosmic_fmu_set_start_time(instance, "fmi3EnterInitializationMode", startTime);
  if (status != COSMIC_FMU_OK) {
    return (fmi3Status)status;
  }
  return (fmi3Status)cosmic_fmu_enter_initialization(instance, "fmi3EnterInitializationMode");
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
  if (instance == NULL) {
    return fmi3Error;
  }
  return (fmi3Status)cosmic_fmu_exit_initialization(instance, "fmi3ExitInitializationMode");
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
  return instance == NULL ? fmi3Error : (fmi3Status)cosmic_fmu_terminate(instance, "fmi3Terminate");
}

fmi3Status fmi3Reset(fmi3Instance instance) {
  return instance == NULL ? fmi3Error : (fmi3Status)cosmic_fmu_reset(instance);
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean* eventHandlingNeeded,
                      fmi3Boolean* terminateSimulation, fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime) {
  (void)noSetFMUStatePriorToCurrentPoint; /* no FMU state is kept for rolling back */
  if (instance == NULL || eventHandlingNeeded == NULL || terminateSimulation == NULL || earlyReturn == NULL ||
      lastSuccessfulTime == NULL) {
    return fmi3Error;
  }
  *eventHandlingNeeded = false;
  *terminateSimulation = false;
  *earlyReturn = false;
  const cosmic_fmu_status status =
      cosmic_fmu_do_step(instance, "fmi3DoStep", currentCommunicationPoint, communicationStepSize);
  *lastSuccessfulTime = ((cosmic_fmu_instance*)instance)->time;
  return (fmi3Status)status;
}

/* Scalars only: one value per value reference. */
static bool one_value_each(fmi3Instance instance, const char* function, size_t nValueReferences, size_t nValues) {
  if (nValues == nValueReferences) {
    return true;
  }
  cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "%s: %zu values for %zu value references (every variable is a scalar)",
                 function, nValues, nValueReferences);
  return false;
}

#define COSMIC_FMI3_GET(T, KIND, STORED)                                                                    \
  fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3##T values[], \
                        size_t nValues) {                                                                   \
    if (instance == NULL || cosmic_fmu_begin_get(instance, "fmi3Get" #T) >= COSMIC_FMU_ERROR ||             \
        !one_value_each(instance, "fmi3Get" #T, nvr, nValues)) {                                            \
      return fmi3Error;                                                                                     \
    }                                                                                                       \
    for (size_t i = 0; i < nvr; ++i) {                                                                      \
      STORED const* stored = cosmic_fmu_readable(instance, "fmi3Get" #T, vr[i], KIND);                      \
      if (stored == NULL) {                                                                                 \
        return fmi3Error;                                                                                   \
      }                                                                                                     \
      values[i] = *stored;                                                                                  \
    }                                                                                                       \
    return fmi3OK;                                                                                          \
  }

#define COSMIC_FMI3_SET(T, KIND, STORED, ASSIGN)                                                                  \
  fmi3Status fmi3Set##T(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3##T values[], \
                        size_t nValues) {                                                                         \
    if (instance == NULL || cosmic_fmu_begin_set(instance, "fmi3Set" #T) >= COSMIC_FMU_ERROR ||                   \
        !one_value_each(instance, "fmi3Set" #T, nvr, nValues)) {                                                  \
      return fmi3Error;                                                                                           \
    }                                                                                                             \
    for (size_t i = 0; i < nvr; ++i) {                                                                            \
      STORED* stored = cosmic_fmu_writable(instance, "fmi3Set" #T, vr[i], KIND);                                  \
      if (stored == NULL || ASSIGN(instance, stored, values[i]) != COSMIC_FMU_OK) {                               \
        return fmi3Error;                                                                                         \
      }                                                                                                           \
    }                                                                                                             \
    return fmi3OK;                                                                                                \
  }

/* A number or a boolean is copied; a string is copied into the instance. */
#define COSMIC_FMI3_COPY(instance, stored, value) (*(stored) = (value), COSMIC_FMU_OK)

static cosmic_fmu_status assign_string(cosmic_fmu_instance* instance, char** stored, fmi3String value) {
  if (value == NULL) {
    return cosmic_fmu_log(instance, COSMIC_FMU_ERROR, "fmi3SetString: a value is NULL");
  }
  return cosmic_fmu_assign_string(instance, stored, value, "");
}

#define COSMIC_FMI3_GET_SET_NUMBER(T, KIND) \
  COSMIC_FMI3_GET(T, KIND, fmi3##T)         \
  COSMIC_FMI3_SET(T, KIND, fmi3##T, COSMIC_FMI3_COPY)

COSMIC_FMI3_GET_SET_NUMBER(Float32, COSMIC_FMU_FLOAT32)
COSMIC_FMI3_GET_SET_NUMBER(Float64, COSMIC_FMU_FLOAT64)
COSMIC_FMI3_GET_SET_NUMBER(Int8, COSMIC_FMU_INT8)
COSMIC_FMI3_GET_SET_NUMBER(UInt8, COSMIC_FMU_UINT8)
COSMIC_FMI3_GET_SET_NUMBER(Int16, COSMIC_FMU_INT16)
COSMIC_FMI3_GET_SET_NUMBER(UInt16, COSMIC_FMU_UINT16)
COSMIC_FMI3_GET_SET_NUMBER(Int32, COSMIC_FMU_INT32)
COSMIC_FMI3_GET_SET_NUMBER(UInt32, COSMIC_FMU_UINT32)
COSMIC_FMI3_GET_SET_NUMBER(Int64, COSMIC_FMU_INT64)
COSMIC_FMI3_GET_SET_NUMBER(UInt64, COSMIC_FMU_UINT64)
COSMIC_FMI3_GET_SET_NUMBER(Boolean, COSMIC_FMU_BOOLEAN)
COSMIC_FMI3_GET(String, COSMIC_FMU_STRING, char*)
COSMIC_FMI3_SET(String, COSMIC_FMU_STRING, char*, assign_string)
