// The tests' FMI importer: fmu_driver.hpp.
#include "fmu_driver.hpp"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <type_traits>

#include "cosmic/build_paths.hpp"
#include "cosmic/fmi2_api.h"
#include "cosmic/fmi3_api.h"
#include "cosmic/fmu_archive.hpp"

namespace cosmic::test {

namespace fs = std::filesystem;

std::string test_fmu_path(std::string_view name, int version) {
  return std::string(build_paths::test_fmu_dir) + "/" + std::string(name) + "-fmi" + std::to_string(version) + ".fmu";
}

LoadedFmu::LoadedFmu(const std::string& fmu_path) {
  std::string pattern = (fs::temp_directory_path() / "cosmic-fmi-model-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    error_ = "cannot make a directory from " + pattern;
    return;
  }
  work_dir_ = pattern;
  const fmi::FmuOpenResult opened = fmi::open_fmu(fmu_path, work_dir_ + "/fmu");
  for (const std::string& e : opened.errors) error_ += e + "\n";
  if (!opened.ok()) return;
  description_ = opened.fmu.description;
  handle_ = ::dlopen(opened.fmu.binary.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle_ == nullptr) error_ = std::string("dlopen: ") + ::dlerror();
}

LoadedFmu::~LoadedFmu() {
  if (handle_ != nullptr) ::dlclose(handle_);
  std::error_code ignored;
  if (!work_dir_.empty()) fs::remove_all(work_dir_, ignored);
}

const fmi::Variable* LoadedFmu::variable(std::string_view name) const {
  const fmi::Variable* found = description_.find_variable(name);
  if (found == nullptr) ADD_FAILURE() << description_.model_name << " has no variable " << name;
  return found;
}

void* LoadedFmu::symbol(const char* name) const { return handle_ != nullptr ? ::dlsym(handle_, name) : nullptr; }

const char* to_string(Status status) {
  static const char* const names[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
  const auto index = static_cast<std::size_t>(status);
  return index < std::size(names) ? names[index] : "(not a status)";
}

void Model::record(Status status, const char* category, const char* message) {
  log_.push_back({status, category != nullptr ? category : "", message != nullptr ? message : ""});
}

std::string Model::log_text() const {
  std::string text;
  for (const LogRecord& r : log_)
    text += std::string(to_string(r.status)) + " [" + r.category + "] " + r.message + "\n";
  return text;
}

Status Model::set(std::string_view name, const Value& value) {
  const fmi::Variable* variable = fmu_.variable(name);
  return variable != nullptr ? set(*variable, value) : Status::fatal;
}

Value Model::get(std::string_view name) {
  Value value;
  const fmi::Variable* variable = fmu_.variable(name);
  if (variable == nullptr) return value;
  const Status status = get(*variable, value);
  if (status != Status::ok) ADD_FAILURE() << "get " << name << ": " << to_string(status) << "\n" << log_text();
  return value;
}

double Model::get_float(std::string_view name) {
  const Value value = get(name);
  return std::holds_alternative<double>(value) ? std::get<double>(value) : -1e300;
}

namespace {

// Any number of a Value as T (the tests choose values the type holds), a string as itself.
template <class T>
T value_as(const Value& value) {
  return std::visit(
      [](const auto& v) -> T {
        using V = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<V, std::string> || std::is_same_v<T, std::string>) {
          if constexpr (std::is_same_v<V, T>) return v;
          ADD_FAILURE() << "a string and a number do not convert";
          return T{};
        } else {
          return static_cast<T>(v);
        }
      },
      value);
}

class Fmi2Model final : public Model {
 public:
  Fmi2Model(const LoadedFmu& fmu, const std::string& name, bool logging_on) : Model(fmu) {
    auto* instantiate = fmu.function<fmi2InstantiateTYPE>("fmi2Instantiate");
    if (instantiate == nullptr) {
      ADD_FAILURE() << "no fmi2Instantiate";
      return;
    }
    instance_ = instantiate(name.c_str(), fmi2CoSimulation, fmu.description().instantiation_token.c_str(), nullptr,
                            &callbacks_, fmi2False, logging_on ? fmi2True : fmi2False);
  }
  ~Fmi2Model() override {
    if (instance_ != nullptr) fmu_.function<fmi2FreeInstanceTYPE>("fmi2FreeInstance")(instance_);
  }

  Status enter_initialization(double start_time) override {
    const auto status =
        call<fmi2SetupExperimentTYPE>("fmi2SetupExperiment", instance_, fmi2False, 0.0, start_time, fmi2False, 0.0);
    if (status != Status::ok) return status;
    return call<fmi2EnterInitializationModeTYPE>("fmi2EnterInitializationMode", instance_);
  }
  Status exit_initialization() override {
    return call<fmi2ExitInitializationModeTYPE>("fmi2ExitInitializationMode", instance_);
  }
  Status do_step(double t, double h) override { return call<fmi2DoStepTYPE>("fmi2DoStep", instance_, t, h, fmi2True); }
  Status terminate() override { return call<fmi2TerminateTYPE>("fmi2Terminate", instance_); }
  Status reset() override { return call<fmi2ResetTYPE>("fmi2Reset", instance_); }

  Status set(const fmi::Variable& variable, const Value& value) override {
    const fmi2ValueReference vr[] = {variable.value_reference};
    switch (variable.type) {
      case fmi::VariableType::float64: {
        const fmi2Real v[] = {value_as<double>(value)};
        return call<fmi2SetRealTYPE>("fmi2SetReal", instance_, vr, 1, v);
      }
      case fmi::VariableType::int32:
      case fmi::VariableType::enumeration: {
        const fmi2Integer v[] = {value_as<fmi2Integer>(value)};
        return call<fmi2SetIntegerTYPE>("fmi2SetInteger", instance_, vr, 1, v);
      }
      case fmi::VariableType::boolean: {
        const fmi2Boolean v[] = {value_as<bool>(value) ? fmi2True : fmi2False};
        return call<fmi2SetBooleanTYPE>("fmi2SetBoolean", instance_, vr, 1, v);
      }
      case fmi::VariableType::string: {
        const std::string text = value_as<std::string>(value);
        const fmi2String v[] = {text.c_str()};
        return call<fmi2SetStringTYPE>("fmi2SetString", instance_, vr, 1, v);
      }
      default:
        ADD_FAILURE() << variable.name << " is of no FMI 2.0 type";
        return Status::fatal;
    }
  }

  Status get(const fmi::Variable& variable, Value& value) override {
    const fmi2ValueReference vr[] = {variable.value_reference};
    Status status = Status::fatal;
    switch (variable.type) {
      case fmi::VariableType::float64: {
        fmi2Real v[1] = {};
        status = call<fmi2GetRealTYPE>("fmi2GetReal", instance_, vr, 1, v);
        value = v[0];
        break;
      }
      case fmi::VariableType::int32:
      case fmi::VariableType::enumeration: {
        fmi2Integer v[1] = {};
        status = call<fmi2GetIntegerTYPE>("fmi2GetInteger", instance_, vr, 1, v);
        value = std::int64_t{v[0]};
        break;
      }
      case fmi::VariableType::boolean: {
        fmi2Boolean v[1] = {};
        status = call<fmi2GetBooleanTYPE>("fmi2GetBoolean", instance_, vr, 1, v);
        value = v[0] != fmi2False;
        break;
      }
      case fmi::VariableType::string: {
        fmi2String v[1] = {};
        status = call<fmi2GetStringTYPE>("fmi2GetString", instance_, vr, 1, v);
        value = std::string(v[0] != nullptr ? v[0] : "(null)");
        break;
      }
      default:
        ADD_FAILURE() << variable.name << " is of no FMI 2.0 type";
    }
    return status;
  }

 private:
  // The standard's logger: `message` is a printf format for the arguments that follow.
  static void logger(fmi2ComponentEnvironment environment, fmi2String, fmi2Status status, fmi2String category,
                     fmi2String message, ...) {
    char text[2048];
    va_list arguments;
    va_start(arguments, message);
    std::vsnprintf(text, sizeof text, message, arguments);
    va_end(arguments);
    static_cast<Fmi2Model*>(environment)->record(static_cast<Status>(status), category, text);
  }

  const fmi2CallbackFunctions callbacks_{&Fmi2Model::logger, &std::calloc, &std::free, nullptr, this};
};

class Fmi3Model final : public Model {
 public:
  Fmi3Model(const LoadedFmu& fmu, const std::string& name, bool logging_on, bool event_mode_used) : Model(fmu) {
    auto* instantiate = fmu.function<fmi3InstantiateCoSimulationTYPE>("fmi3InstantiateCoSimulation");
    if (instantiate == nullptr) {
      ADD_FAILURE() << "no fmi3InstantiateCoSimulation";
      return;
    }
    instance_ = instantiate(name.c_str(), fmu.description().instantiation_token.c_str(), nullptr, false, logging_on,
                            event_mode_used, false, nullptr, 0, this, &Fmi3Model::logger, nullptr);
  }
  ~Fmi3Model() override {
    if (instance_ != nullptr) fmu_.function<fmi3FreeInstanceTYPE>("fmi3FreeInstance")(instance_);
  }

  Status enter_initialization(double start_time) override {
    return call<fmi3EnterInitializationModeTYPE>("fmi3EnterInitializationMode", instance_, false, 0.0, start_time,
                                                 false, 0.0);
  }
  Status exit_initialization() override {
    return call<fmi3ExitInitializationModeTYPE>("fmi3ExitInitializationMode", instance_);
  }
  Status do_step(double t, double h) override {
    report_ = Fmi3StepReport{};
    return call<fmi3DoStepTYPE>("fmi3DoStep", instance_, t, h, true, &report_.event_handling_needed,
                                &report_.terminate_simulation, &report_.early_return, &report_.last_successful_time);
  }
  Status terminate() override { return call<fmi3TerminateTYPE>("fmi3Terminate", instance_); }
  Status reset() override { return call<fmi3ResetTYPE>("fmi3Reset", instance_); }

  Status set(const fmi::Variable& variable, const Value& value) override {
    return with_type(variable, [&]<class T, class Stored>(const std::string& type) {
      const fmi3ValueReference vr[] = {variable.value_reference};
      using Setter = fmi3Status(fmi3Instance, const fmi3ValueReference[], size_t, const T[], size_t);
      if constexpr (std::is_same_v<T, fmi3String>) {
        const std::string text = value_as<std::string>(value);
        const T v[] = {text.c_str()};
        return call<Setter>(("fmi3Set" + type).c_str(), instance_, vr, 1, v, 1);
      } else {
        const T v[] = {value_as<T>(value)};
        return call<Setter>(("fmi3Set" + type).c_str(), instance_, vr, 1, v, 1);
      }
    });
  }

  Status get(const fmi::Variable& variable, Value& value) override {
    return with_type(variable, [&]<class T, class Stored>(const std::string& type) {
      const fmi3ValueReference vr[] = {variable.value_reference};
      using Getter = fmi3Status(fmi3Instance, const fmi3ValueReference[], size_t, T[], size_t);
      T v[1] = {};
      const Status status = call<Getter>(("fmi3Get" + type).c_str(), instance_, vr, 1, v, 1);
      if constexpr (std::is_same_v<T, fmi3String>) {
        value = std::string(v[0] != nullptr ? v[0] : "(null)");
      } else {
        value = static_cast<Stored>(v[0]);
      }
      return status;
    });
  }

  const Fmi3StepReport& report() const { return report_; }

 private:
  // Calls action<T, Stored>(TYPE) with the C type of the variable's fmi3Get/SetTYPE functions and
  // the Value alternative that holds it (enumerations go through fmi3GetInt64).
  template <class Action>
  static Status with_type(const fmi::Variable& variable, Action&& action) {
    using fmi::VariableType;
    switch (variable.type) {
      case VariableType::float32:
        return action.template operator()<fmi3Float32, double>("Float32");
      case VariableType::float64:
        return action.template operator()<fmi3Float64, double>("Float64");
      case VariableType::int8:
        return action.template operator()<fmi3Int8, std::int64_t>("Int8");
      case VariableType::uint8:
        return action.template operator()<fmi3UInt8, std::uint64_t>("UInt8");
      case VariableType::int16:
        return action.template operator()<fmi3Int16, std::int64_t>("Int16");
      case VariableType::uint16:
        return action.template operator()<fmi3UInt16, std::uint64_t>("UInt16");
      case VariableType::int32:
        return action.template operator()<fmi3Int32, std::int64_t>("Int32");
      case VariableType::uint32:
        return action.template operator()<fmi3UInt32, std::uint64_t>("UInt32");
      case VariableType::int64:
      case VariableType::enumeration:
        return action.template operator()<fmi3Int64, std::int64_t>("Int64");
      case VariableType::uint64:
        return action.template operator()<fmi3UInt64, std::uint64_t>("UInt64");
      case VariableType::boolean:
        return action.template operator()<fmi3Boolean, bool>("Boolean");
      case VariableType::string:
        return action.template operator()<fmi3String, std::string>("String");
      default:
        ADD_FAILURE() << variable.name << " is of a type the test FMUs do not use";
        return Status::fatal;
    }
  }

  static void logger(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category, fmi3String message) {
    static_cast<Fmi3Model*>(environment)->record(static_cast<Status>(status), category, message);
  }

  Fmi3StepReport report_;
};

}  // namespace

std::unique_ptr<Model> Model::instantiate(const LoadedFmu& fmu, const std::string& name, bool logging_on) {
  if (fmu.version() == fmi::FmiVersion::fmi2) return std::make_unique<Fmi2Model>(fmu, name, logging_on);
  return std::make_unique<Fmi3Model>(fmu, name, logging_on, false);
}

std::unique_ptr<Model> instantiate_fmi3(const LoadedFmu& fmu, const std::string& name, bool logging_on,
                                        bool event_mode_used) {
  return std::make_unique<Fmi3Model>(fmu, name, logging_on, event_mode_used);
}

const Fmi3StepReport& last_step_report(const Model& fmi3_model) {
  return dynamic_cast<const Fmi3Model&>(fmi3_model).report();
}

}  // namespace cosmic::test
