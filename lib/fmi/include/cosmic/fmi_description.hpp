// What an FMU's modelDescription.xml says (FMI 2.0 and 3.x; issue 38, docs/fmu.md): its FMI version,
// names, co-simulation interface, default experiment and every variable, as a plain value.
//
// parse_model_description() reads the XML text (tinyxml2) and reports every problem with its line;
// it does no I/O and never throws. The FMU archive around it is fmu_archive.hpp's.
//
// Threads: plain values and a pure function; any thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cosmic::fmi {

// Bounds on what one description may cost (a generated model of 100,000 variables is about 30 MB).
inline constexpr std::size_t kMaxDescriptionBytes = 64u << 20;
inline constexpr std::size_t kMaxVariables = 200'000;
inline constexpr std::size_t kMaxTypeDefinitions = 20'000;
inline constexpr std::size_t kMaxEnumerationItems = 10'000;  // of one enumeration type
inline constexpr std::size_t kMaxReportedProblems = 50;      // the rest are counted in one closing entry

enum class FmiVersion : std::uint8_t { fmi2, fmi3 };

enum class Causality : std::uint8_t {
  parameter,
  calculated_parameter,
  input,
  output,
  local,
  independent,
  structural_parameter,  // FMI 3.0 only
};

enum class Variability : std::uint8_t { constant, fixed, tunable, discrete, continuous };

// A variable's type. FMI 2.0's Real is float64, its Integer int32 (what fmi2GetReal / fmi2GetInteger
// carry); Binary and Clock exist in FMI 3.0 only.
enum class VariableType : std::uint8_t {
  float32,
  float64,
  int8,
  uint8,
  int16,
  uint16,
  int32,
  uint32,
  int64,
  uint64,
  boolean,
  string,
  binary,
  enumeration,
  clock,
};

// The spelling of the XML: "parameter", "calculatedParameter", ...; "fixed", ...; and the type's
// element name in the given version ("Real" / "Float64", "Integer" / "Int32", ...).
std::string_view to_string(Causality causality);
std::string_view to_string(Variability variability);
std::string_view type_element(VariableType type, FmiVersion version);
bool is_float(VariableType type);
bool is_integer(VariableType type);  // Int8 ... UInt64 (FMI 2.0 Integer); not Enumeration
// The values an integer type (or an enumeration: int32 in 2.0, int64 in 3.0) holds.
std::pair<double, double> integer_limits(VariableType type, FmiVersion version);

struct EnumerationItem {
  std::string name;
  std::int64_t value = 0;
  friend bool operator==(const EnumerationItem&, const EnumerationItem&) = default;
};

// A type of <TypeDefinitions>: FMI 2.0 <SimpleType name><Real unit/></SimpleType>, FMI 3.0
// <Float64Type name unit/>, <EnumerationType name><Item name value/></EnumerationType>, ...
struct TypeDefinition {
  std::string name;
  VariableType type = VariableType::float64;
  std::string unit;           // floats; empty: none
  std::optional<double> min;  // numbers and enumerations: the declared range; none: the type's
  std::optional<double> max;
  std::vector<EnumerationItem> items;  // enumerations, as declared
  int line = 0;
  friend bool operator==(const TypeDefinition&, const TypeDefinition&) = default;
};

// One dimension of an FMI 3.0 array variable: a fixed length, or the structural parameter that holds it.
struct Dimension {
  std::optional<std::uint64_t> start;
  std::optional<std::uint32_t> value_reference;
  friend bool operator==(const Dimension&, const Dimension&) = default;
};

struct Variable {
  std::string name;
  std::uint32_t value_reference = 0;
  Causality causality = Causality::local;
  Variability variability = Variability::continuous;
  VariableType type = VariableType::float64;
  // The start value as written: the `start` attribute's text (an array's: its values separated by
  // spaces), or the values of FMI 3.0 <Start value> elements (String, Binary), in order. Empty: none.
  std::vector<std::string> start;
  std::string unit;           // the variable's own or its declared type's; empty: none
  std::optional<double> min;  // the declared range, the variable's own or its declared type's; none: the type's
  std::optional<double> max;
  std::string declared_type;  // empty: none
  std::string description;
  // FMI 3.0 arrays (<Dimension> elements), recorded; empty: a scalar. The configuration refuses to
  // map an array variable (docs/fmu.md).
  std::vector<Dimension> dimensions;
  // FMI 3.0 <Alias>: another name for `alias_of`'s value (same value reference); empty: none.
  std::string alias_of;
  int line = 0;
  friend bool operator==(const Variable&, const Variable&) = default;
};

// The <CoSimulation> element. FMI 2.0 flags and FMI 3.0 flags where they exist in the version read;
// the rest keep their defaults (false, none).
struct CoSimulation {
  std::string model_identifier;  // the shared library's name without ".so"
  bool can_handle_variable_communication_step_size = false;
  bool needs_execution_tool = false;
  bool can_be_instantiated_only_once_per_process = false;
  bool can_get_and_set_fmu_state = false;
  bool can_interpolate_inputs = false;             // FMI 2.0
  std::optional<double> fixed_internal_step_size;  // FMI 3.0, seconds
  bool has_event_mode = false;                     // FMI 3.0
  bool might_return_early_from_do_step = false;    // FMI 3.0
  bool provides_intermediate_update = false;       // FMI 3.0
  int line = 0;
  friend bool operator==(const CoSimulation&, const CoSimulation&) = default;
};

struct DefaultExperiment {  // seconds; none: not given
  std::optional<double> start_time;
  std::optional<double> stop_time;
  std::optional<double> tolerance;
  std::optional<double> step_size;
  friend bool operator==(const DefaultExperiment&, const DefaultExperiment&) = default;
};

struct FmuDescription {
  FmiVersion version = FmiVersion::fmi2;
  std::string fmi_version;  // as written: "2.0", "3.0", "3.1"
  std::string model_name;
  std::string instantiation_token;            // FMI 3.0 instantiationToken, FMI 2.0 guid
  std::optional<CoSimulation> co_simulation;  // none: refused (model exchange only) when parsed
  bool model_exchange = false;                // a <ModelExchange> element is there too
  DefaultExperiment default_experiment;
  std::vector<TypeDefinition> type_definitions;
  std::vector<Variable> variables;  // in document order, FMI 3.0 aliases after the variable they name

  const Variable* find_variable(std::string_view name) const;
  const TypeDefinition* find_type(std::string_view name) const;
  friend bool operator==(const FmuDescription&, const FmuDescription&) = default;
};

// A problem of the description: its line in modelDescription.xml (0: the whole text, or the closing
// count of problems not reported) and what is wrong.
struct DescriptionProblem {
  int line = 0;
  std::string message;
  // "modelDescription.xml:LINE: message" (no line: "modelDescription.xml: message").
  std::string to_string() const;
  friend bool operator==(const DescriptionProblem&, const DescriptionProblem&) = default;
};

struct DescriptionResult {
  FmuDescription description;  // meaningful only when problems is empty
  std::vector<DescriptionProblem> problems;
  bool ok() const { return problems.empty(); }
};

// Reads modelDescription.xml. Refused, each with its line: text beyond kMaxDescriptionBytes,
// malformed XML, a root other than <fmiModelDescription>, an fmiVersion other than 2.0 or 3.x, a
// missing required attribute (fmiVersion, modelName, guid / instantiationToken, modelIdentifier, a
// variable's name and valueReference), a value that does not parse (a number, a boolean, a
// causality, a variability), no <CoSimulation> element, duplicate variable or type names, a value
// reference used twice for variables the FMU cannot tell apart (FMI 3.0: any two variables; FMI 2.0:
// two variables of different types read by the same fmi2Get function, such as an Integer and an
// Enumeration: in 2.0 same-typed variables sharing one are aliases, and each fmi2GetXXX has its own
// references), a variable type element that is unknown, a declaredType that names no type of the
// same kind, an Enumeration without one, and more than kMaxVariables variables.
DescriptionResult parse_model_description(std::string_view xml);

}  // namespace cosmic::fmi
