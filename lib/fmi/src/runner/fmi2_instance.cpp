// An FMI 2.0 co-simulation instance (cosmic/fmu_instance.hpp; FMI 2.0.4 sections 2.1 and 4).
#include <cstdarg>
#include <cstdio>
#include <cstdlib>

#include "cosmic/fmi2_api.h"
#include "fmu_library.hpp"

namespace cosmic::fmi::runner_detail {
namespace {

const char* fmi2_status_name(fmi2Status s) {
  switch (s) {
    case fmi2OK:
      return "OK";
    case fmi2Warning:
      return "Warning";
    case fmi2Discard:
      return "Discard";
    case fmi2Error:
      return "Error";
    case fmi2Fatal:
      return "Fatal";
    case fmi2Pending:
      return "Pending";
  }
  return "unknown status";
}

// The standard's logger: `message` is a printf format the FMU wrote, for the arguments it passed.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
void fmi2_log(fmi2ComponentEnvironment environment, fmi2String, fmi2Status status, fmi2String category,
              fmi2String message, ...) {
  if (environment == nullptr) return;
  char text[kMaxLogLineBytes + 1] = "";
  if (message != nullptr) {
    va_list arguments;
    va_start(arguments, message);
    std::vsnprintf(text, sizeof text, message, arguments);
    va_end(arguments);
  }
  try {  // nothing may leave a callback through the FMU's C frames
    static_cast<FmuInstance*>(environment)->keep_log({fmi2_status_name(status), category ? category : "", text});
  } catch (...) {
  }
}
#pragma GCC diagnostic pop

struct Fmi2Functions {
  fmi2GetVersionTYPE* get_version = nullptr;
  fmi2InstantiateTYPE* instantiate = nullptr;
  fmi2FreeInstanceTYPE* free_instance = nullptr;
  fmi2SetupExperimentTYPE* setup_experiment = nullptr;
  fmi2EnterInitializationModeTYPE* enter_initialization = nullptr;
  fmi2ExitInitializationModeTYPE* exit_initialization = nullptr;
  fmi2TerminateTYPE* terminate = nullptr;
  fmi2GetRealTYPE* get_real = nullptr;
  fmi2GetIntegerTYPE* get_integer = nullptr;
  fmi2GetBooleanTYPE* get_boolean = nullptr;
  fmi2GetStringTYPE* get_string = nullptr;
  fmi2SetRealTYPE* set_real = nullptr;
  fmi2SetIntegerTYPE* set_integer = nullptr;
  fmi2SetBooleanTYPE* set_boolean = nullptr;
  fmi2SetStringTYPE* set_string = nullptr;
  fmi2DoStepTYPE* do_step = nullptr;
};

Result<Fmi2Functions> resolve_fmi2(const SharedLibrary& lib) {
  Fmi2Functions f;
  std::string missing;
  const auto take = [&]<typename F>(F*& into, const char* name) {
    auto found = lib.function<F>(name);
    if (found) {
      into = found.value();
    } else if (missing.empty()) {
      missing = found.error().text;
    }
  };
  take(f.get_version, "fmi2GetVersion");
  take(f.instantiate, "fmi2Instantiate");
  take(f.free_instance, "fmi2FreeInstance");
  take(f.setup_experiment, "fmi2SetupExperiment");
  take(f.enter_initialization, "fmi2EnterInitializationMode");
  take(f.exit_initialization, "fmi2ExitInitializationMode");
  take(f.terminate, "fmi2Terminate");
  take(f.get_real, "fmi2GetReal");
  take(f.get_integer, "fmi2GetInteger");
  take(f.get_boolean, "fmi2GetBoolean");
  take(f.get_string, "fmi2GetString");
  take(f.set_real, "fmi2SetReal");
  take(f.set_integer, "fmi2SetInteger");
  take(f.set_boolean, "fmi2SetBoolean");
  take(f.set_string, "fmi2SetString");
  take(f.do_step, "fmi2DoStep");
  if (!missing.empty()) return Error{missing};
  return f;
}

class Fmi2Instance final : public FmuInstance {
 public:
  Fmi2Instance(std::shared_ptr<SharedLibrary> library, Fmi2Functions f) : library_(std::move(library)), f_(f) {}
  ~Fmi2Instance() override {
    if (component_ == nullptr) return;
    if (initialized_ && !failed_) f_.terminate(component_);
    if (!fatal_) f_.free_instance(component_);
  }

  Result<void> create(const OpenedFmu& fmu, const InstanceOptions& options) {
    const std::string location = file_uri(fmu.resources);
    component_ =
        f_.instantiate(options.instance_name.c_str(), fmi2CoSimulation, fmu.description.instantiation_token.c_str(),
                       location.c_str(), &callbacks_, fmi2False, options.logging_on ? fmi2True : fmi2False);
    if (component_ == nullptr) return Error{"fmi2Instantiate refused" + last_words()};
    return {};
  }

  Result<void> set(const Variable& v, const VariableValue& value) override {
    const fmi2ValueReference vr = v.value_reference;
    fmi2Status s = fmi2Error;
    if (const auto* real = std::get_if<double>(&value)) {
      s = f_.set_real(component_, &vr, 1, real);
    } else if (const auto* whole = std::get_if<std::int64_t>(&value)) {
      const auto integer = static_cast<fmi2Integer>(*whole);
      s = f_.set_integer(component_, &vr, 1, &integer);
    } else if (const auto* natural = std::get_if<std::uint64_t>(&value)) {
      const auto integer = static_cast<fmi2Integer>(*natural);
      s = f_.set_integer(component_, &vr, 1, &integer);
    } else if (const auto* flag = std::get_if<bool>(&value)) {
      const fmi2Boolean boolean = *flag ? fmi2True : fmi2False;
      s = f_.set_boolean(component_, &vr, 1, &boolean);
    } else if (const auto* text = std::get_if<std::string>(&value)) {
      const fmi2String string = text->c_str();
      s = f_.set_string(component_, &vr, 1, &string);
    }
    return checked(s, "fmi2Set", &v);
  }

  Result<VariableValue> get(const Variable& v) override {
    const fmi2ValueReference vr = v.value_reference;
    fmi2Status s = fmi2Error;
    VariableValue out;
    if (is_float(v.type)) {
      fmi2Real real = 0;
      s = f_.get_real(component_, &vr, 1, &real);
      out = real;
    } else if (v.type == VariableType::boolean) {
      fmi2Boolean boolean = fmi2False;
      s = f_.get_boolean(component_, &vr, 1, &boolean);
      out = boolean != fmi2False;
    } else if (v.type == VariableType::string) {
      fmi2String string = nullptr;
      s = f_.get_string(component_, &vr, 1, &string);
      out = std::string(string ? string : "");
    } else {
      fmi2Integer integer = 0;
      s = f_.get_integer(component_, &vr, 1, &integer);
      out = std::int64_t{integer};
    }
    if (auto ok = checked(s, "fmi2Get", &v); !ok) return ok.error();
    return out;
  }

  Result<void> initialize(double start_time) override {
    if (auto ok =
            checked(f_.setup_experiment(component_, fmi2False, 0.0, start_time, fmi2False, 0.0), "fmi2SetupExperiment");
        !ok)
      return ok;
    if (auto ok = checked(f_.enter_initialization(component_), "fmi2EnterInitializationMode"); !ok) return ok;
    if (auto ok = checked(f_.exit_initialization(component_), "fmi2ExitInitializationMode"); !ok) return ok;
    initialized_ = true;
    return {};
  }

  Result<void> do_step(double time, double step) override {
    return checked(f_.do_step(component_, time, step, fmi2True), "fmi2DoStep");
  }

  Result<void> terminate() override {
    if (!initialized_ || failed_) return {};
    initialized_ = false;
    return checked(f_.terminate(component_), "fmi2Terminate");
  }

 private:
  // OK and Warning go on; Discard, Error and Fatal stop the runner (a co-simulation step discarded
  // is one the runner cannot repeat: it has no earlier state to go back to). After Discard the FMU
  // may still be terminated; after Error or Fatal not (and after Fatal not even freed). The error's
  // text is built only on failure: the step thread allocates nothing for a call that went well.
  Result<void> checked(fmi2Status s, const char* call, const Variable* variable = nullptr) {
    if (s == fmi2OK || s == fmi2Warning) return {};
    failed_ = failed_ || s != fmi2Discard;
    fatal_ = fatal_ || s == fmi2Fatal;
    const std::string what = variable ? std::string(call) + " of '" + variable->name + "'" : std::string(call);
    return Error{what + " returned " + fmi2_status_name(s) + last_words()};
  }

  std::shared_ptr<SharedLibrary> library_;
  Fmi2Functions f_;
  // The FMU keeps a pointer to this until fmi2FreeInstance; `this` is its environment.
  const fmi2CallbackFunctions callbacks_{fmi2_log, std::calloc, std::free, nullptr, this};
  fmi2Component component_ = nullptr;
  bool initialized_ = false;
  bool failed_ = false;
  bool fatal_ = false;  // after Fatal not even fmi2FreeInstance may be called
};

}  // namespace

Result<std::unique_ptr<FmuInstance>> instantiate_fmi2(std::shared_ptr<SharedLibrary> library, const OpenedFmu& fmu,
                                                      const InstanceOptions& options) {
  auto functions = resolve_fmi2(*library);
  if (!functions) return functions.error();
  const std::string version = functions.value().get_version ? functions.value().get_version() : "";
  if (version != "2.0")
    return Error{library->path() + ": fmi2GetVersion says '" + version + "', the description says 2.0"};
  auto instance = std::make_unique<Fmi2Instance>(std::move(library), functions.value());
  if (auto created = instance->create(fmu, options); !created) return created.error();
  return std::unique_ptr<FmuInstance>(std::move(instance));
}

}  // namespace cosmic::fmi::runner_detail
