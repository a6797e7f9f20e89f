/* The part of the test FMUs (issue 38, docs/fmu.md "Test models") that does not depend on the FMI
 * version nor on the model: one instance's state machine, its variables found by value reference,
 * its log messages and its strings. fmi2_functions.c and fmi3_functions.c put the FMI 2.0 and
 * FMI 3.0 C API over it; a model (plant.c, speed_controller.c, every_type.c) gives a table of its
 * variables and the functions that compute them (cosmic_fmu_model below).
 *
 * Ownership: an instance owns its model variables and every string in them; they are freed with
 * the instance. Nothing is global, so a process may hold any number of instances.
 * Threads: an instance is used by one thread at a time (the FMI standard's rule); distinct
 * instances are independent. */
#ifndef COSMIC_TEST_FMU_INSTANCE_H
#define COSMIC_TEST_FMU_INSTANCE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The values of fmi2Status and fmi3Status, which agree on these five. */
typedef enum {
  COSMIC_FMU_OK = 0,
  COSMIC_FMU_WARNING = 1,
  COSMIC_FMU_DISCARD = 2,
  COSMIC_FMU_ERROR = 3,
  COSMIC_FMU_FATAL = 4,
} cosmic_fmu_status;

/* How a variable is stored in the model's struct: float, double, int8_t ... uint64_t, bool, and
 * char* (a string the instance owns). An FMI 2.0 Integer or Enumeration is INT32, an FMI 3.0
 * Enumeration INT64 (what fmi2GetInteger and fmi3GetInt64 carry). */
typedef enum {
  COSMIC_FMU_FLOAT32,
  COSMIC_FMU_FLOAT64,
  COSMIC_FMU_INT8,
  COSMIC_FMU_UINT8,
  COSMIC_FMU_INT16,
  COSMIC_FMU_UINT16,
  COSMIC_FMU_INT32,
  COSMIC_FMU_UINT32,
  COSMIC_FMU_INT64,
  COSMIC_FMU_UINT64,
  COSMIC_FMU_BOOLEAN,
  COSMIC_FMU_STRING,
} cosmic_fmu_kind;

/* A variable's causality and variability as far as setting it is concerned. */
typedef enum {
  COSMIC_FMU_INDEPENDENT,       /* the time: read from the instance, never set */
  COSMIC_FMU_FIXED_PARAMETER,   /* set before initialization ends */
  COSMIC_FMU_TUNABLE_PARAMETER, /* set before initialization and between steps */
  COSMIC_FMU_INPUT,             /* set before initialization and between steps */
  COSMIC_FMU_OUTPUT,            /* computed by the model, never set */
  COSMIC_FMU_LOCAL,             /* computed by the model, never set; readable for tests */
} cosmic_fmu_role;

typedef union {
  double real; /* FLOAT32, FLOAT64 */
  int64_t integer;
  uint64_t unsigned_integer;
  bool boolean;
  const char* string;
} cosmic_fmu_start;

/* One row of a model's variable table: its modelDescription.xml name and value reference, how it is
 * stored (at `offset` in the model's struct; unused for the independent variable), and its start
 * value (inputs and parameters: the description's `start`; others: unused). */
typedef struct {
  const char* name;
  uint32_t value_reference;
  cosmic_fmu_kind kind;
  cosmic_fmu_role role;
  size_t offset;
  cosmic_fmu_start start;
} cosmic_fmu_variable;

typedef struct cosmic_fmu_instance cosmic_fmu_instance;

/* What a model gives: the token its modelDescription.xml names (FMI 2.0 guid, FMI 3.0
 * instantiationToken), the size of its variables' struct, its variable table and three functions,
 * each given the instance (cosmic_fmu_model_variables() is the struct) and returning a status after
 * logging why it is not OK:
 *  - calculate_outputs: the outputs from the inputs and parameters as they are at initialization
 *    (called before any read during initialization and when initialization ends);
 *  - check_parameters: when initialization ends, before calculate_outputs; an Error refuses them;
 *  - do_step: one communication step from t to t + h (h >= 0). */
typedef struct {
  const char* instantiation_token;
  size_t variables_size;
  const cosmic_fmu_variable* variables;
  size_t variable_count;
  cosmic_fmu_status (*calculate_outputs)(cosmic_fmu_instance*);
  cosmic_fmu_status (*check_parameters)(cosmic_fmu_instance*);
  cosmic_fmu_status (*do_step)(cosmic_fmu_instance*, double t, double h);
} cosmic_fmu_model;

/* Each model defines this one (its table and functions); the API files read it. */
extern const cosmic_fmu_model cosmic_fmu_this_model;

/* Where the instance's memory and messages go: the FMI 2.0 callbacks or FMI 3.0's plain allocation
 * and logMessage. allocate returns zeroed memory or NULL. log gets the formatted message. */
typedef struct {
  void* (*allocate)(size_t count, size_t size);
  void (*release)(void*);
  void (*log)(const cosmic_fmu_instance*, cosmic_fmu_status, const char* category, const char* message);
  const void* context; /* the FMI 2.0 callback functions or the FMI 3.0 callback; read by `log` */
  void* environment;   /* the importer's componentEnvironment / instanceEnvironment */
} cosmic_fmu_host;

typedef enum {
  COSMIC_FMU_INSTANTIATED,
  COSMIC_FMU_INITIALIZATION_MODE,
  COSMIC_FMU_STEP_MODE,
  COSMIC_FMU_TERMINATED,
  COSMIC_FMU_FAILED, /* a call returned Error: only reads, terminate, reset and free are accepted */
} cosmic_fmu_state;

struct cosmic_fmu_instance {
  cosmic_fmu_host host;
  const cosmic_fmu_model* model;
  char* name;
  unsigned logged_categories; /* a bit per category of cosmic_fmu_log: set, it is logged */
  cosmic_fmu_state state;
  double time; /* the start time, then the end of the last successful step */
  void* variables;
};

/* Allocates an instance with the model's start values; NULL when memory runs out. `name` is
 * copied. */
cosmic_fmu_instance* cosmic_fmu_create(const cosmic_fmu_model* model, const cosmic_fmu_host* host, const char* name,
                                       bool logging_on);
void cosmic_fmu_destroy(cosmic_fmu_instance* instance);
/* Back to the instantiated state and the start values (fmi2Reset, fmi3Reset). */
cosmic_fmu_status cosmic_fmu_reset(cosmic_fmu_instance* instance);

/* Whether `function` may be called in the instance's state: when not, it is logged and false. */
bool cosmic_fmu_allowed(cosmic_fmu_instance* instance, const char* function, unsigned allowed_states);
#define COSMIC_FMU_IN(state) (1u << (state))

/* The state machine's transitions; each checks the state it starts from. */
cosmic_fmu_status cosmic_fmu_set_start_time(cosmic_fmu_instance* instance, const char* function, double start_time);
cosmic_fmu_status cosmic_fmu_enter_initialization(cosmic_fmu_instance* instance, const char* function);
cosmic_fmu_status cosmic_fmu_exit_initialization(cosmic_fmu_instance* instance, const char* function);
cosmic_fmu_status cosmic_fmu_do_step(cosmic_fmu_instance* instance, const char* function, double t, double h);
cosmic_fmu_status cosmic_fmu_terminate(cosmic_fmu_instance* instance, const char* function);

/* Reads and writes: a Get (Set) function first calls cosmic_fmu_begin_get (begin_set), which checks
 * the state (reads: from initialization on; writes: until termination) and, during
 * initialization, lets the model calculate its outputs; then, for each value reference, the
 * variable's storage for a value of `kind`: NULL, logged, when there is no such variable, it has
 * another kind, or it may not be written now (an output; a fixed parameter after initialization). */
cosmic_fmu_status cosmic_fmu_begin_get(cosmic_fmu_instance* instance, const char* function);
cosmic_fmu_status cosmic_fmu_begin_set(cosmic_fmu_instance* instance, const char* function);
const void* cosmic_fmu_readable(cosmic_fmu_instance* instance, const char* function, uint32_t value_reference,
                                cosmic_fmu_kind kind);
void* cosmic_fmu_writable(cosmic_fmu_instance* instance, const char* function, uint32_t value_reference,
                          cosmic_fmu_kind kind);

/* For the models: their variables' struct, a variable by value reference (NULL: none), and a string
 * variable's slot set to `prefix` followed by `suffix` (a copy the instance owns). */
void* cosmic_fmu_model_variables(cosmic_fmu_instance* instance);
const cosmic_fmu_variable* cosmic_fmu_find_variable(const cosmic_fmu_instance* instance, uint32_t value_reference);
cosmic_fmu_status cosmic_fmu_assign_string(cosmic_fmu_instance* instance, char** slot, const char* prefix,
                                           const char* suffix);

/* Logs a message (printf format) with the category of its status ("logStatusError", ...) when
 * logging is on; returns `status`. */
cosmic_fmu_status cosmic_fmu_log(const cosmic_fmu_instance* instance, cosmic_fmu_status status, const char* format, ...)
    __attribute__((format(printf, 3, 4)));

/* fmi2SetDebugLogging / fmi3SetDebugLogging: no categories: logging on or off; else each must be
 * one of the categories cosmic_fmu_log uses (modelDescription.xml's <LogCategories>). */
cosmic_fmu_status cosmic_fmu_set_logging(cosmic_fmu_instance* instance, const char* function, bool on,
                                         size_t category_count, const char* const categories[]);

#endif
