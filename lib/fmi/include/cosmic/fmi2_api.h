/* The FMI 2.0 co-simulation C API that cosmic-fmu calls and the test models implement, written
 * from the standard (FMI 2.0.4, sections 2.1 and 4.2): the platform types, the callbacks and the
 * function types an FMU's shared library exports under their plain names (fmi2DoStep, ...).
 * Only what co-simulation uses is declared; model exchange and the state/derivative functions are
 * left out (cosmic-fmu never calls them).
 *
 * A model that defines COSMIC_FMI2_EXPORTS before including this gets the prototypes too, so its
 * definitions are checked against these types. */
#ifndef COSMIC_FMI2_API_H
#define COSMIC_FMI2_API_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef void* fmi2Component;
typedef void* fmi2ComponentEnvironment;
typedef void* fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char* fmi2String;
typedef char fmi2Byte;

#define fmi2True 1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

/* `message` is a printf format for the arguments that follow (the standard's logger). */
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String instanceName, fmi2Status, fmi2String category,
                                   fmi2String message, ...);
typedef void* (*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void*);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

/* The FMU keeps a pointer to this until fmi2FreeInstance: the caller keeps it alive that long. */
typedef struct {
  const fmi2CallbackLogger logger;
  const fmi2CallbackAllocateMemory allocateMemory;
  const fmi2CallbackFreeMemory freeMemory;
  const fmi2StepFinished stepFinished;
  const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef const char* fmi2GetTypesPlatformTYPE(void);
typedef const char* fmi2GetVersionTYPE(void);
typedef fmi2Status fmi2SetDebugLoggingTYPE(fmi2Component, fmi2Boolean, size_t, const fmi2String[]);
/* fmuResourceLocation: a URI ("file:///abs/resources"). */
typedef fmi2Component fmi2InstantiateTYPE(fmi2String instanceName, fmi2Type, fmi2String fmuGUID,
                                          fmi2String fmuResourceLocation, const fmi2CallbackFunctions*,
                                          fmi2Boolean visible, fmi2Boolean loggingOn);
typedef void fmi2FreeInstanceTYPE(fmi2Component);
typedef fmi2Status fmi2SetupExperimentTYPE(fmi2Component, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                           fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime);
typedef fmi2Status fmi2EnterInitializationModeTYPE(fmi2Component);
typedef fmi2Status fmi2ExitInitializationModeTYPE(fmi2Component);
typedef fmi2Status fmi2TerminateTYPE(fmi2Component);
typedef fmi2Status fmi2ResetTYPE(fmi2Component);
typedef fmi2Status fmi2GetRealTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]);
typedef fmi2Status fmi2GetIntegerTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2Integer[]);
typedef fmi2Status fmi2GetBooleanTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2Boolean[]);
typedef fmi2Status fmi2GetStringTYPE(fmi2Component, const fmi2ValueReference[], size_t, fmi2String[]);
typedef fmi2Status fmi2SetRealTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]);
typedef fmi2Status fmi2SetIntegerTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[]);
typedef fmi2Status fmi2SetBooleanTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Boolean[]);
typedef fmi2Status fmi2SetStringTYPE(fmi2Component, const fmi2ValueReference[], size_t, const fmi2String[]);
typedef fmi2Status fmi2DoStepTYPE(fmi2Component, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                                  fmi2Boolean noSetFMUStatePriorToCurrentPoint);
typedef fmi2Status fmi2CancelStepTYPE(fmi2Component);
typedef fmi2Status fmi2GetStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Status*);
typedef fmi2Status fmi2GetRealStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Real*);
typedef fmi2Status fmi2GetIntegerStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Integer*);
typedef fmi2Status fmi2GetBooleanStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2Boolean*);
typedef fmi2Status fmi2GetStringStatusTYPE(fmi2Component, const fmi2StatusKind, fmi2String*);

#ifdef COSMIC_FMI2_EXPORTS
#define COSMIC_FMI2_EXPORT __attribute__((visibility("default")))
COSMIC_FMI2_EXPORT fmi2GetTypesPlatformTYPE fmi2GetTypesPlatform;
COSMIC_FMI2_EXPORT fmi2GetVersionTYPE fmi2GetVersion;
COSMIC_FMI2_EXPORT fmi2SetDebugLoggingTYPE fmi2SetDebugLogging;
COSMIC_FMI2_EXPORT fmi2InstantiateTYPE fmi2Instantiate;
COSMIC_FMI2_EXPORT fmi2FreeInstanceTYPE fmi2FreeInstance;
COSMIC_FMI2_EXPORT fmi2SetupExperimentTYPE fmi2SetupExperiment;
COSMIC_FMI2_EXPORT fmi2EnterInitializationModeTYPE fmi2EnterInitializationMode;
COSMIC_FMI2_EXPORT fmi2ExitInitializationModeTYPE fmi2ExitInitializationMode;
COSMIC_FMI2_EXPORT fmi2TerminateTYPE fmi2Terminate;
COSMIC_FMI2_EXPORT fmi2ResetTYPE fmi2Reset;
COSMIC_FMI2_EXPORT fmi2GetRealTYPE fmi2GetReal;
COSMIC_FMI2_EXPORT fmi2GetIntegerTYPE fmi2GetInteger;
COSMIC_FMI2_EXPORT fmi2GetBooleanTYPE fmi2GetBoolean;
COSMIC_FMI2_EXPORT fmi2GetStringTYPE fmi2GetString;
COSMIC_FMI2_EXPORT fmi2SetRealTYPE fmi2SetReal;
COSMIC_FMI2_EXPORT fmi2SetIntegerTYPE fmi2SetInteger;
COSMIC_FMI2_EXPORT fmi2SetBooleanTYPE fmi2SetBoolean;
COSMIC_FMI2_EXPORT fmi2SetStringTYPE fmi2SetString;
COSMIC_FMI2_EXPORT fmi2DoStepTYPE fmi2DoStep;
COSMIC_FMI2_EXPORT fmi2CancelStepTYPE fmi2CancelStep;
COSMIC_FMI2_EXPORT fmi2GetStatusTYPE fmi2GetStatus;
COSMIC_FMI2_EXPORT fmi2GetRealStatusTYPE fmi2GetRealStatus;
COSMIC_FMI2_EXPORT fmi2GetIntegerStatusTYPE fmi2GetIntegerStatus;
COSMIC_FMI2_EXPORT fmi2GetBooleanStatusTYPE fmi2GetBooleanStatus;
COSMIC_FMI2_EXPORT fmi2GetStringStatusTYPE fmi2GetStringStatus;
#endif

#ifdef __cplusplus
}
#endif

#endif
