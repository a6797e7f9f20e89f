/* The FMI 3.0 co-simulation C API that cosmic-fmu calls and the test models implement, written
 * from the standard (FMI 3.0.1, sections 2.2 and 4.2): the platform types, the callbacks and the
 * function types an FMU's shared library exports under their plain names (fmi3DoStep, ...).
 * Only what co-simulation without event mode uses is declared: cosmic-fmu instantiates with
 * eventModeUsed and earlyReturnAllowed false, so the FMU goes from initialization straight to
 * step mode, and it never asks for intermediate updates.
 *
 * A model that defines COSMIC_FMI3_EXPORTS before including this gets the prototypes too, so its
 * definitions are checked against these types. */
#ifndef COSMIC_FMI3_API_H
#define COSMIC_FMI3_API_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef void* fmi3Instance;
typedef void* fmi3InstanceEnvironment;
typedef void* fmi3FMUState;
typedef uint32_t fmi3ValueReference;
typedef float fmi3Float32;
typedef double fmi3Float64;
typedef int8_t fmi3Int8;
typedef uint8_t fmi3UInt8;
typedef int16_t fmi3Int16;
typedef uint16_t fmi3UInt16;
typedef int32_t fmi3Int32;
typedef uint32_t fmi3UInt32;
typedef int64_t fmi3Int64;
typedef uint64_t fmi3UInt64;
typedef bool fmi3Boolean;
typedef char fmi3Char;
typedef const fmi3Char* fmi3String;
typedef uint8_t fmi3Byte;
typedef const fmi3Byte* fmi3Binary;
typedef bool fmi3Clock;

typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;

typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment, fmi3Status, fmi3String category, fmi3String message);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment, fmi3Float64 intermediateUpdateTime,
                                               fmi3Boolean intermediateVariableSetRequested,
                                               fmi3Boolean intermediateVariableGetAllowed,
                                               fmi3Boolean intermediateStepFinished, fmi3Boolean canReturnEarly,
                                               fmi3Boolean* earlyReturnRequested, fmi3Float64* earlyReturnTime);

typedef const char* fmi3GetVersionTYPE(void);
typedef fmi3Status fmi3SetDebugLoggingTYPE(fmi3Instance, fmi3Boolean loggingOn, size_t nCategories,
                                           const fmi3String categories[]);
/* resourcePath: an absolute directory path ending in '/', or NULL when the FMU has no resources. */
typedef fmi3Instance fmi3InstantiateCoSimulationTYPE(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference requiredIntermediateVariables[], size_t nRequiredIntermediateVariables,
    fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
    fmi3IntermediateUpdateCallback intermediateUpdate);
typedef void fmi3FreeInstanceTYPE(fmi3Instance);
typedef fmi3Status fmi3EnterInitializationModeTYPE(fmi3Instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                                   fmi3Float64 startTime, fmi3Boolean stopTimeDefined,
                                                   fmi3Float64 stopTime);
typedef fmi3Status fmi3ExitInitializationModeTYPE(fmi3Instance);
typedef fmi3Status fmi3TerminateTYPE(fmi3Instance);
typedef fmi3Status fmi3ResetTYPE(fmi3Instance);

#define COSMIC_FMI3_GET_SET(T)                                                                              \
  typedef fmi3Status fmi3Get##T##TYPE(fmi3Instance, const fmi3ValueReference[], size_t, fmi3##T[], size_t); \
  typedef fmi3Status fmi3Set##T##TYPE(fmi3Instance, const fmi3ValueReference[], size_t, const fmi3##T[], size_t);
COSMIC_FMI3_GET_SET(Float32)
COSMIC_FMI3_GET_SET(Float64)
COSMIC_FMI3_GET_SET(Int8)
COSMIC_FMI3_GET_SET(UInt8)
COSMIC_FMI3_GET_SET(Int16)
COSMIC_FMI3_GET_SET(UInt16)
COSMIC_FMI3_GET_SET(Int32)
COSMIC_FMI3_GET_SET(UInt32)
COSMIC_FMI3_GET_SET(Int64)
COSMIC_FMI3_GET_SET(UInt64)
COSMIC_FMI3_GET_SET(Boolean)
COSMIC_FMI3_GET_SET(String)
#undef COSMIC_FMI3_GET_SET

typedef fmi3Status fmi3DoStepTYPE(fmi3Instance, fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation,
                                  fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime);

#ifdef COSMIC_FMI3_EXPORTS
#define COSMIC_FMI3_EXPORT __attribute__((visibility("default")))
COSMIC_FMI3_EXPORT fmi3GetVersionTYPE fmi3GetVersion;
COSMIC_FMI3_EXPORT fmi3SetDebugLoggingTYPE fmi3SetDebugLogging;
COSMIC_FMI3_EXPORT fmi3InstantiateCoSimulationTYPE fmi3InstantiateCoSimulation;
COSMIC_FMI3_EXPORT fmi3FreeInstanceTYPE fmi3FreeInstance;
COSMIC_FMI3_EXPORT fmi3EnterInitializationModeTYPE fmi3EnterInitializationMode;
COSMIC_FMI3_EXPORT fmi3ExitInitializationModeTYPE fmi3ExitInitializationMode;
COSMIC_FMI3_EXPORT fmi3TerminateTYPE fmi3Terminate;
COSMIC_FMI3_EXPORT fmi3ResetTYPE fmi3Reset;
#define COSMIC_FMI3_EXPORT_GET_SET(T)             \
  COSMIC_FMI3_EXPORT fmi3Get##T##TYPE fmi3Get##T; \
  COSMIC_FMI3_EXPORT fmi3Set##T##TYPE fmi3Set##T;
COSMIC_FMI3_EXPORT_GET_SET(Float32)
COSMIC_FMI3_EXPORT_GET_SET(Float64)
COSMIC_FMI3_EXPORT_GET_SET(Int8)
COSMIC_FMI3_EXPORT_GET_SET(UInt8)
COSMIC_FMI3_EXPORT_GET_SET(Int16)
COSMIC_FMI3_EXPORT_GET_SET(UInt16)
COSMIC_FMI3_EXPORT_GET_SET(Int32)
COSMIC_FMI3_EXPORT_GET_SET(UInt32)
COSMIC_FMI3_EXPORT_GET_SET(Int64)
COSMIC_FMI3_EXPORT_GET_SET(UInt64)
COSMIC_FMI3_EXPORT_GET_SET(Boolean)
COSMIC_FMI3_EXPORT_GET_SET(String)
#undef COSMIC_FMI3_EXPORT_GET_SET
COSMIC_FMI3_EXPORT fmi3DoStepTYPE fmi3DoStep;
#endif

#ifdef __cplusplus
}
#endif

#endif
