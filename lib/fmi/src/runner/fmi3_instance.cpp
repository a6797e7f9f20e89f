// An FMI 3.0 co-simulation instance (cosmic/fmu_instance.hpp; FMI 3.0.1 sections 2.3 and 4), without
// event mode: after initialization the FMU is in step mode.
#include <filesystem>

#include "cosmic/fmi3_api.h"
#include "fmu_library.hpp"

namespace cosmic::fmi::runner_detail {
namespace {

const char* fmi3_status_name(fmi3Status s) {
  switch (s) {
    case fmi3OK:
      return "OK";
    case fmi3Warning:
      return "Warning";
    case fmi3Discard:
      return "Discard";
    case fmi3Error:
      return "Error";
    case fmi3Fatal:
      return "Fatal";
  }
  return "unknown status";
}

void fmi3_log(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category, fmi3String message) {
  if (environment == nullptr) return;
  try {  // nothing may leave a callback through the FMU's C frames
    static_cast<FmuInstance*>(environment)
        ->keep_log({fmi3_status_name(status), category ? category : "", message ? message : ""});
  } catch (...) {
  }
}

// One type's get and set functions.
template <typename T>
struct Accessors {
  fmi3Status (*get)(fmi3Instance, const fmi3ValueReference[], size_t, T[], size_t) = nullptr;
  fmi3Status (*set)(fmi3Instance, const fmi3ValueReference[], size_t, const T[], size_t) = nullptr;
};

struct Fmi3Functions {
  fmi3GetVersionTYPE* get_version = nullptr;
  fmi3InstantiateCoSimulationTYPE* instantiate = nullptr;
  fmi3FreeInstanceTYPE* free_instance = nullptr;
  fmi3EnterInitializationModeTYPE* enter_initialization = nullptr;
  fmi3ExitInitializationModeTYPE* exit_initialization = nullptr;
  fmi3TerminateTYPE* terminate = nullptr;
  fmi3DoStepTYPE* do_step = nullptr;
  Accessors<fmi3Float32> float32;
  Accessors<fmi3Float64> float64;
  Accessors<fmi3Int8> int8;
  Accessors<fmi3UInt8> uint8;
  Accessors<fmi3Int16> int16;
  Accessors<fmi3UInt16> uint16;
  Accessors<fmi3Int32> int32;
  Accessors<fmi3UInt32> uint32;
  Accessors<fmi3Int64> int64;
  Accessors<fmi3UInt64> uint64;
  Accessors<fmi3Boolean> boolean;
  Accessors<fmi3String> string;
};

Result<Fmi3Functions> resolve_fmi3(const SharedLibrary& lib) {
  Fmi3Functions f;
  std::string missing;
  const auto take = [&]<typename F>(F*& into, const std::string& name) {
    auto found = lib.function<F>(name.c_str());
    if (found) {
      into = found.value();
    } else if (missing.empty()) {
      missing = found.error().text;
    }
  };
  const auto accessors = [&]<typename T>(Accessors<T>& into, const std::string& type) {
    using Get = fmi3Status(fmi3Instance, const fmi3ValueReference[], size_t, T[], size_t);
    using Set = fmi3Status(fmi3Instance, const fmi3ValueReference[], size_t, const T[], size_t);
    take.template operator()<Get>(into.get, "fmi3Get" + type);
    take.template operator()<Set>(into.set, "fmi3Set" + type);
  };
  take(f.get_version, "fmi3GetVersion");
  take(f.instantiate, "fmi3InstantiateCoSimulation");
  take(f.free_instance, "fmi3FreeInstance");
  take(f.enter_initialization, "fmi3EnterInitializationMode");
  take(f.exit_initialization, "fmi3ExitInitializationMode");
  take(f.terminate, "fmi3Terminate");
  take(f.do_step, "fmi3DoStep");
  accessors(f.float32, "Float32");
  accessors(f.float64, "Float64");
  accessors(f.int8, "Int8");
  accessors(f.uint8, "UInt8");
  accessors(f.int16, "Int16");
  accessors(f.uint16, "UInt16");
  accessors(f.int32, "Int32");
  accessors(f.uint32, "UInt32");
  accessors(f.int64, "Int64");
  accessors(f.uint64, "UInt64");
  accessors(f.boolean, "Boolean");
  accessors(f.string, "String");
  if (!missing.empty()) return Error{missing};
  return f;
}

class Fmi3Instance final : public FmuInstance {
 public:
  Fmi3Instance(std::shared_ptr<SharedLibrary> library, Fmi3Functions f) : library_(std::move(library)), f_(f) {}
  ~Fmi3Instance() override {
    if (instance_ == nullptr) return;
    if (initialized_ && !failed_) f_.terminate(instance_);
    if (!fatal_) f_.free_instance(instance_);
  }

  Result<void> create(const OpenedFmu& fmu, const InstanceOptions& options) {
    // The FMU's resources directory with its trailing '/', or NULL when it has none (FMI 3.0 2.3.1).
    std::error_code ignored;
    const bool has_resources = !fmu.resources.empty() && !std::filesystem::is_empty(fmu.resources, ignored);
    const std::string resources = has_resources && fmu.resources.back() != '/' ? fmu.resources + "/" : fmu.resources;
    instance_ =
        f_.instantiate(options.instance_name.c_str(), fmu.description.instantiation_token.c_str(),
                       has_resources ? resources.c_str() : nullptr, false, options.logging_on, /*eventModeUsed=*/false,
                       /*earlyReturnAllowed=*/false, nullptr, 0, this, fmi3_log, nullptr);
    if (instance_ == nullptr) return Error{"fmi3InstantiateCoSimulation refused" + last_words()};
    return {};
  }

  Result<void> set(const Variable& v, const VariableValue& value) override {
    return checked(set_value(v, value), "fmi3Set", &v);
  }

  Result<VariableValue> get(const Variable& v) override {
    VariableValue out;
    if (auto ok = checked(get_value(v, out), "fmi3Get", &v); !ok) return ok.error();
    return out;
  }

  Result<void> initialize(double start_time) override {
    if (auto ok = checked(f_.enter_initialization(instance_, false, 0.0, start_time, false, 0.0),
                          "fmi3EnterInitializationMode");
        !ok)
      return ok;
    if (auto ok = checked(f_.exit_initialization(instance_), "fmi3ExitInitializationMode"); !ok) return ok;
    initialized_ = true;
    return {};
  }

  Result<void> do_step(double time, double step) override {
    fmi3Boolean event_needed = false, terminate = false, early = false;
    fmi3Float64 last_time = time;
    if (auto ok = checked(f_.do_step(instance_, time, step, true, &event_needed, &terminate, &early, &last_time),
                          "fmi3DoStep");
        !ok)
      return ok;
    // terminateSimulation: the step succeeded and the FMU is done; the runner publishes this step's
    // outputs, terminates the FMU (fmi3Terminate, as the standard asks) and stops.
    if (terminate) mark_ended();
    return {};
  }

  Result<void> terminate() override {
    if (!initialized_ || failed_) return {};
    initialized_ = false;
    return checked(f_.terminate(instance_), "fmi3Terminate");
  }

 private:
  template <typename T, typename Held>
  fmi3Status set_as(const Accessors<T>& a, const Variable& v, Held value) {
    const fmi3ValueReference vr = v.value_reference;
    const T converted = static_cast<T>(value);
    return a.set(instance_, &vr, 1, &converted, 1);
  }
  template <typename T, typename Held>
  fmi3Status get_as(const Accessors<T>& a, const Variable& v, VariableValue& out) {
    const fmi3ValueReference vr = v.value_reference;
    T value{};
    const fmi3Status s = a.get(instance_, &vr, 1, &value, 1);
    out = static_cast<Held>(value);
    return s;
  }

  fmi3Status set_value(const Variable& v, const VariableValue& value) {
    if (const auto* text = std::get_if<std::string>(&value)) {
      const fmi3ValueReference vr = v.value_reference;
      const fmi3String string = text->c_str();
      return f_.string.set(instance_, &vr, 1, &string, 1);
    }
    // Numbers and Booleans, whichever alternative holds them, as the variable's type.
    const double real = std::visit(
        [](const auto& x) -> double {
          if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::string>) {
            return 0.0;
          } else {
            return static_cast<double>(x);
          }
        },
        value);
    const auto* whole = std::get_if<std::int64_t>(&value);
    const auto* natural = std::get_if<std::uint64_t>(&value);
    const std::int64_t s = whole     ? *whole
                           : natural ? static_cast<std::int64_t>(*natural)
                                     : static_cast<std::int64_t>(real);
    const std::uint64_t u = natural ? *natural
                            : whole ? static_cast<std::uint64_t>(*whole)
                                    : static_cast<std::uint64_t>(real);
    switch (v.type) {
      case VariableType::float32:
        return set_as(f_.float32, v, real);
      case VariableType::float64:
        return set_as(f_.float64, v, real);
      case VariableType::int8:
        return set_as(f_.int8, v, s);
      case VariableType::uint8:
        return set_as(f_.uint8, v, u);
      case VariableType::int16:
        return set_as(f_.int16, v, s);
      case VariableType::uint16:
        return set_as(f_.uint16, v, u);
      case VariableType::int32:
        return set_as(f_.int32, v, s);
      case VariableType::uint32:
        return set_as(f_.uint32, v, u);
      case VariableType::int64:
      case VariableType::enumeration:
        return set_as(f_.int64, v, s);
      case VariableType::uint64:
        return set_as(f_.uint64, v, u);
      case VariableType::boolean:
        return set_as(f_.boolean, v, std::holds_alternative<bool>(value) ? std::get<bool>(value) : real != 0.0);
      default:
        return fmi3Error;
    }
  }

  fmi3Status get_value(const Variable& v, VariableValue& out) {
    switch (v.type) {
      case VariableType::float32:
        return get_as<fmi3Float32, double>(f_.float32, v, out);
      case VariableType::float64:
        return get_as<fmi3Float64, double>(f_.float64, v, out);
      case VariableType::int8:
        return get_as<fmi3Int8, std::int64_t>(f_.int8, v, out);
      case VariableType::uint8:
        return get_as<fmi3UInt8, std::uint64_t>(f_.uint8, v, out);
      case VariableType::int16:
        return get_as<fmi3Int16, std::int64_t>(f_.int16, v, out);
      case VariableType::uint16:
        return get_as<fmi3UInt16, std::uint64_t>(f_.uint16, v, out);
      case VariableType::int32:
        return get_as<fmi3Int32, std::int64_t>(f_.int32, v, out);
      case VariableType::uint32:
        return get_as<fmi3UInt32, std::uint64_t>(f_.uint32, v, out);
      case VariableType::int64:
      case VariableType::enumeration:
        return get_as<fmi3Int64, std::int64_t>(f_.int64, v, out);
      case VariableType::uint64:
        return get_as<fmi3UInt64, std::uint64_t>(f_.uint64, v, out);
      case VariableType::boolean:
        return get_as<fmi3Boolean, bool>(f_.boolean, v, out);
      case VariableType::string: {
        const fmi3ValueReference vr = v.value_reference;
        fmi3String string = nullptr;
        const fmi3Status s = f_.string.get(instance_, &vr, 1, &string, 1);
        out = std::string(string ? string : "");
        return s;
      }
      default:
        return fmi3Error;
    }
  }

  // As Fmi2Instance::checked: Discard still lets the FMU be terminated, Error and Fatal do not; the
  // error's text is built only on failure.
  Result<void> checked(fmi3Status s, const char* call, const Variable* variable = nullptr) {
    if (s == fmi3OK || s == fmi3Warning) return {};
    failed_ = failed_ || s != fmi3Discard;
    fatal_ = fatal_ || s == fmi3Fatal;
    const std::string what = variable ? std::string(call) + " of '" + variable->name + "'" : std::string(call);
    return Error{what + " returned " + fmi3_status_name(s) + last_words()};
  }

  std::shared_ptr<SharedLibrary> library_;
  Fmi3Functions f_;
  fmi3Instance instance_ = nullptr;
  bool initialized_ = false;
  bool failed_ = false;
  bool fatal_ = false;
};

}  // namespace

Result<std::unique_ptr<FmuInstance>> instantiate_fmi3(std::shared_ptr<SharedLibrary> library, const OpenedFmu& fmu,
                                                      const InstanceOptions& options) {
  auto functions = resolve_fmi3(*library);
  if (!functions) return functions.error();
  const std::string version = functions.value().get_version ? functions.value().get_version() : "";
  if (version.rfind("3.", 0) != 0)
    return Error{library->path() + ": fmi3GetVersion says '" + version + "', the description says " +
                 fmu.description.fmi_version};
  auto instance = std::make_unique<Fmi3Instance>(std::move(library), functions.value());
  if (auto created = instance->create(fmu, options); !created) return created.error();
  return std::unique_ptr<FmuInstance>(std::move(instance));
}

}  // namespace cosmic::fmi::runner_detail
