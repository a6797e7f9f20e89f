// A minimal FMI importer for the tests of the test FMUs (tests/fmi_models): an FMU opened with
// cosmic::fmi::open_fmu into a private directory, its binary loaded with dlopen, and instances
// driven through the standard's calling sequence (FMI 2.0 and 3.0 co-simulation). It is the tests'
// own, independent of the runner cosmic-fmu.
//
// Ownership: a LoadedFmu owns the loaded library and its directory; a Model owns one instance of
// it and must be destroyed first (declare the LoadedFmu before the Model). Threads: the test's.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "cosmic/fmi_description.hpp"

namespace cosmic::test {

// The test FMU <name>-fmi<version>.fmu built by tests/fmi_models/CMakeLists.txt.
std::string test_fmu_path(std::string_view name, int version);

// The names of a test run for FMI 2.0 and 3.0 (a parameter of 2 or 3): Fmi2, Fmi3.
inline std::string fmi_version_label(const testing::TestParamInfo<int>& info) {
  return "Fmi" + std::to_string(info.param);
}

class LoadedFmu {
 public:
  explicit LoadedFmu(const std::string& fmu_path);
  ~LoadedFmu();
  LoadedFmu(const LoadedFmu&) = delete;
  LoadedFmu& operator=(const LoadedFmu&) = delete;

  bool ok() const { return handle_ != nullptr; }
  const std::string& error() const { return error_; }  // why it is not ok
  const fmi::FmuDescription& description() const { return description_; }
  fmi::FmiVersion version() const { return description_.version; }
  // The variable of that name; nullptr (and a test failure) when there is none.
  const fmi::Variable* variable(std::string_view name) const;
  // An exported function of the binary; nullptr when it does not export it.
  void* symbol(const char* name) const;
  template <class Function>
  Function* function(const char* name) const {
    return reinterpret_cast<Function*>(symbol(name));
  }

 private:
  std::string work_dir_;
  void* handle_ = nullptr;
  fmi::FmuDescription description_;
  std::string error_;
};

// fmi2Status / fmi3Status.
enum class Status : int { ok, warning, discard, error, fatal, pending };
const char* to_string(Status status);

struct LogRecord {
  Status status = Status::ok;
  std::string category;
  std::string message;  // formatted (FMI 2.0's logger gets a printf format)
};

// A variable's value: floats as double, signed integers and enumerations as int64, unsigned
// integers as uint64. Setting converts any number to the variable's type.
using Value = std::variant<double, std::int64_t, std::uint64_t, bool, std::string>;

// One instance of a loaded FMU, driven through its version's functions.
class Model {
 public:
  // Instantiates (fmi2Instantiate for co-simulation with the description's guid, or
  // fmi3InstantiateCoSimulation without event mode); instantiated() says whether it worked.
  static std::unique_ptr<Model> instantiate(const LoadedFmu& fmu, const std::string& name = "instance",
                                            bool logging_on = true);
  virtual ~Model() = default;
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  bool instantiated() const { return instance_ != nullptr; }
  void* instance() const { return instance_; }  // the fmi2Component / fmi3Instance, for calls of a test's own
  // FMI 2.0: fmi2SetupExperiment and fmi2EnterInitializationMode; FMI 3.0: fmi3EnterInitializationMode.
  virtual Status enter_initialization(double start_time = 0.0) = 0;
  virtual Status exit_initialization() = 0;
  virtual Status do_step(double t, double h) = 0;
  virtual Status terminate() = 0;
  virtual Status reset() = 0;
  virtual Status set(const fmi::Variable& variable, const Value& value) = 0;
  virtual Status get(const fmi::Variable& variable, Value& value) = 0;

  // By name; the value read, and a test failure when the call is not OK.
  Status set(std::string_view name, const Value& value);
  Value get(std::string_view name);
  double get_float(std::string_view name);

  const std::vector<LogRecord>& log() const { return log_; }
  std::string log_text() const;  // every message, one a line, for failure reports
  void clear_log() { log_.clear(); }

 protected:
  explicit Model(const LoadedFmu& fmu) : fmu_(fmu) {}
  void record(Status status, const char* category, const char* message);
  // Calls the binary's function `name` of type Function; a test failure when it does not export it.
  template <class Function, class... Arguments>
  Status call(const char* name, Arguments... arguments) {
    auto* function = fmu_.function<Function>(name);
    if (function == nullptr) {
      ADD_FAILURE() << "the FMU does not export " << name;
      return Status::fatal;
    }
    return static_cast<Status>(function(arguments...));
  }

  const LoadedFmu& fmu_;
  void* instance_ = nullptr;
  std::vector<LogRecord> log_;
};

// What fmi3DoStep's last call reported through its output arguments (set to values it must
// overwrite before each call).
struct Fmi3StepReport {
  bool event_handling_needed = true;
  bool terminate_simulation = true;
  bool early_return = true;
  double last_successful_time = -1.0;
};

// The FMI 3.0 instance with the instantiation arguments a test may vary, and the step report.
std::unique_ptr<Model> instantiate_fmi3(const LoadedFmu& fmu, const std::string& name, bool logging_on,
                                        bool event_mode_used);
const Fmi3StepReport& last_step_report(const Model& fmi3_model);

}  // namespace cosmic::test
