// modelDescription.xml: the document, its root attributes, <CoSimulation> and <DefaultExperiment>
// (cosmic/fmi_description.hpp); variables and types are fmi_variables.cpp's.
#include "cosmic/fmi_description.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "description_reader.hpp"

namespace cosmic::fmi {
namespace detail {
namespace {

std::string_view trimmed(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

template <typename T>
std::optional<T> parsed(std::string_view s) {
  s = trimmed(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  T value{};
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

}  // namespace

void DescriptionReader::problem(int line, std::string message) {
  if (problems_.size() < kMaxReportedProblems) {
    problems_.push_back({line, std::move(message)});
  } else {
    ++suppressed_;
  }
}

std::vector<DescriptionProblem> DescriptionReader::take_problems() {
  if (suppressed_ > 0) problems_.push_back({0, std::to_string(suppressed_) + " more problems not shown"});
  suppressed_ = 0;
  return std::move(problems_);
}

int DescriptionReader::attribute_line(const tinyxml2::XMLElement& e, const char* name) const {
  const tinyxml2::XMLAttribute* a = e.FindAttribute(name);
  return a != nullptr ? a->GetLineNum() : e.GetLineNum();
}

std::string DescriptionReader::text(const tinyxml2::XMLElement& e, const char* name) {
  const char* value = e.Attribute(name);
  return value != nullptr ? value : "";
}

std::optional<std::string> DescriptionReader::required(const tinyxml2::XMLElement& e, const char* name,
                                                       bool allow_empty) {
  const char* value = e.Attribute(name);
  if (value == nullptr) {
    problem(e.GetLineNum(), std::string("<") + e.Name() + "> lacks the required attribute '" + name + "'");
    return std::nullopt;
  }
  if (!allow_empty && *value == '\0') {
    problem(attribute_line(e, name), std::string("<") + e.Name() + "> has an empty '" + name + "'");
    return std::nullopt;
  }
  return std::string(value);
}

bool DescriptionReader::flag(const tinyxml2::XMLElement& e, const char* name, bool fallback) {
  const char* value = e.Attribute(name);
  if (value == nullptr) return fallback;
  const std::string_view v = trimmed(value);
  if (v == "true" || v == "1") return true;
  if (v == "false" || v == "0") return false;
  problem(attribute_line(e, name), std::string(name) + "=\"" + value + "\" is not a boolean (true, false, 1 or 0)");
  return fallback;
}

std::optional<double> DescriptionReader::number(const tinyxml2::XMLElement& e, const char* name) {
  const char* value = e.Attribute(name);
  if (value == nullptr) return std::nullopt;
  const auto v = parsed<double>(value);
  if (!v || !std::isfinite(*v)) {
    problem(attribute_line(e, name), std::string(name) + "=\"" + value + "\" is not a finite number");
    return std::nullopt;
  }
  return v;
}

std::optional<std::int64_t> DescriptionReader::whole_number(const tinyxml2::XMLElement& e, const char* name) {
  const char* value = e.Attribute(name);
  if (value == nullptr) return std::nullopt;
  const auto v = parsed<std::int64_t>(value);
  if (!v) problem(attribute_line(e, name), std::string(name) + "=\"" + value + "\" is not a 64-bit whole number");
  return v;
}

std::optional<std::uint64_t> DescriptionReader::unsigned_number(const tinyxml2::XMLElement& e, const char* name,
                                                                std::uint64_t max) {
  const char* value = e.Attribute(name);
  if (value == nullptr) return std::nullopt;
  const auto v = parsed<std::uint64_t>(value);
  if (!v || *v > max) {
    problem(attribute_line(e, name),
            std::string(name) + "=\"" + value + "\" is not a whole number from 0 to " + std::to_string(max));
    return std::nullopt;
  }
  return v;
}

namespace {

class DocumentReader {
 public:
  explicit DocumentReader(DescriptionResult& result) : result_(result), reader_(result.description) {}

  void run(std::string_view xml) {
    if (xml.size() > kMaxDescriptionBytes) {
      reader_.problem(0, "the description has " + std::to_string(xml.size()) + " bytes, more than the " +
                             std::to_string(kMaxDescriptionBytes) + " read");
    } else {
      tinyxml2::XMLDocument document;
      if (document.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
        reader_.problem(document.ErrorLineNum(), std::string("malformed XML: ") + document.ErrorStr());
      } else {
        read_root(document);
      }
    }
    result_.problems = reader_.take_problems();
  }

 private:
  void read_root(const tinyxml2::XMLDocument& document) {
    const tinyxml2::XMLElement* root = document.RootElement();
    if (root == nullptr || std::string_view(root->Name()) != "fmiModelDescription") {
      reader_.problem(root != nullptr ? root->GetLineNum() : 0, std::string("the root element is <") +
                                                                    (root != nullptr ? root->Name() : "") +
                                                                    ">, not <fmiModelDescription>");
      return;
    }
    FmuDescription& d = result_.description;
    if (!read_version(*root)) return;
    if (auto name = reader_.required(*root, "modelName")) d.model_name = *name;
    const char* token = d.version == FmiVersion::fmi2 ? "guid" : "instantiationToken";
    if (auto t = reader_.required(*root, token)) d.instantiation_token = *t;
    for (const tinyxml2::XMLElement* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      const std::string_view name = e->Name();
      if (name == "CoSimulation") {
        read_co_simulation(*e);
      } else if (name == "ModelExchange") {
        d.model_exchange = true;
      } else if (name == "DefaultExperiment") {
        read_default_experiment(*e);
      } else if (name == "TypeDefinitions") {
        reader_.read_type_definitions(*e);
      }
    }
    // Variables after every type, whose units and enumerations they refer to.
    for (const tinyxml2::XMLElement* e = root->FirstChildElement("ModelVariables"); e != nullptr;
         e = e->NextSiblingElement("ModelVariables"))
      reader_.read_variables(*e);
    if (!d.co_simulation) {
      reader_.problem(root->GetLineNum(), d.model_exchange
                                              ? "no <CoSimulation> element: the FMU is for model exchange only "
                                                "(cosmic-fmu steps co-simulation FMUs)"
                                              : "no <CoSimulation> element: the FMU offers no co-simulation");
    }
  }

  bool read_version(const tinyxml2::XMLElement& root) {
    const auto version = reader_.required(root, "fmiVersion");
    if (!version) return false;
    FmuDescription& d = result_.description;
    d.fmi_version = *version;
    const std::string_view v = *version;
    const bool three = v.size() > 2 && v.starts_with("3.") &&
                       std::all_of(v.begin() + 2, v.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (v == "2.0") {
      d.version = FmiVersion::fmi2;
    } else if (three) {
      d.version = FmiVersion::fmi3;
    } else {
      const tinyxml2::XMLAttribute* a = root.FindAttribute("fmiVersion");
      reader_.problem(a->GetLineNum(), "fmiVersion \"" + *version + "\" is not supported (2.0 or 3.x)");
      return false;
    }
    return true;
  }

  void read_co_simulation(const tinyxml2::XMLElement& e) {
    if (result_.description.co_simulation) {
      reader_.problem(e.GetLineNum(), "a second <CoSimulation> element");
      return;
    }
    CoSimulation c;
    c.line = e.GetLineNum();
    if (auto id = reader_.required(e, "modelIdentifier")) c.model_identifier = *id;
    if (!c.model_identifier.empty() && !valid_identifier(c.model_identifier)) {
      reader_.problem(e.GetLineNum(), "modelIdentifier \"" + c.model_identifier +
                                          "\" is not a C identifier (it names the shared library)");
    }
    c.can_handle_variable_communication_step_size = reader_.flag(e, "canHandleVariableCommunicationStepSize");
    c.needs_execution_tool = reader_.flag(e, "needsExecutionTool");
    c.can_be_instantiated_only_once_per_process = reader_.flag(e, "canBeInstantiatedOnlyOncePerProcess");
    if (result_.description.version == FmiVersion::fmi2) {
      c.can_get_and_set_fmu_state = reader_.flag(e, "canGetAndSetFMUstate");
      c.can_interpolate_inputs = reader_.flag(e, "canInterpolateInputs");
    } else {
      c.can_get_and_set_fmu_state = reader_.flag(e, "canGetAndSetFMUState");
      c.fixed_internal_step_size = reader_.number(e, "fixedInternalStepSize");
      c.has_event_mode = reader_.flag(e, "hasEventMode");
      c.might_return_early_from_do_step = reader_.flag(e, "mightReturnEarlyFromDoStep");
      c.provides_intermediate_update = reader_.flag(e, "providesIntermediateUpdate");
    }
    result_.description.co_simulation = c;
  }

  static bool valid_identifier(std::string_view s) {
    const auto letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
    if (s.empty() || !letter(s.front())) return false;
    return std::all_of(s.begin(), s.end(), [&](char c) { return letter(c) || (c >= '0' && c <= '9'); });
  }

  void read_default_experiment(const tinyxml2::XMLElement& e) {
    DefaultExperiment& x = result_.description.default_experiment;
    x.start_time = reader_.number(e, "startTime");
    x.stop_time = reader_.number(e, "stopTime");
    x.tolerance = reader_.number(e, "tolerance");
    x.step_size = reader_.number(e, "stepSize");
    if (x.step_size && *x.step_size <= 0) reader_.problem(e.GetLineNum(), "DefaultExperiment stepSize is not positive");
  }

  DescriptionResult& result_;
  DescriptionReader reader_;
};

}  // namespace
}  // namespace detail

std::string DescriptionProblem::to_string() const {
  return line > 0 ? "modelDescription.xml:" + std::to_string(line) + ": " + message
                  : "modelDescription.xml: " + message;
}

const Variable* FmuDescription::find_variable(std::string_view name) const {
  const auto it = std::find_if(variables.begin(), variables.end(), [&](const Variable& v) { return v.name == name; });
  return it != variables.end() ? &*it : nullptr;
}

const TypeDefinition* FmuDescription::find_type(std::string_view name) const {
  const auto it = std::find_if(type_definitions.begin(), type_definitions.end(),
                               [&](const TypeDefinition& t) { return t.name == name; });
  return it != type_definitions.end() ? &*it : nullptr;
}

DescriptionResult parse_model_description(std::string_view xml) {
  DescriptionResult result;
  detail::DocumentReader(result).run(xml);
  return result;
}

}  // namespace cosmic::fmi
