// modelDescription.xml: <TypeDefinitions> and <ModelVariables> of FMI 2.0 and 3.x, and the names of
// causalities, variabilities and types (cosmic/fmi_description.hpp).
#include <algorithm>
#include <array>
#include <limits>

#include "description_reader.hpp"

namespace cosmic::fmi {
namespace {

struct TypeName {
  VariableType type;
  std::string_view fmi2;  // empty: not in FMI 2.0
  std::string_view fmi3;
};

constexpr std::array<TypeName, 15> kTypes{{
    {VariableType::float32, "", "Float32"},
    {VariableType::float64, "Real", "Float64"},
    {VariableType::int8, "", "Int8"},
    {VariableType::uint8, "", "UInt8"},
    {VariableType::int16, "", "Int16"},
    {VariableType::uint16, "", "UInt16"},
    {VariableType::int32, "Integer", "Int32"},
    {VariableType::uint32, "", "UInt32"},
    {VariableType::int64, "", "Int64"},
    {VariableType::uint64, "", "UInt64"},
    {VariableType::boolean, "Boolean", "Boolean"},
    {VariableType::string, "String", "String"},
    {VariableType::binary, "", "Binary"},
    {VariableType::enumeration, "Enumeration", "Enumeration"},
    {VariableType::clock, "", "Clock"},
}};

constexpr std::array<std::string_view, 7> kCausalities{"parameter",   "calculatedParameter", "input", "output", "local",
                                                       "independent", "structuralParameter"};
constexpr std::array<std::string_view, 5> kVariabilities{"constant", "fixed", "tunable", "discrete", "continuous"};

// The variable type an element of the given version names ("Real", "Float64Type" with `suffix`).
std::optional<VariableType> type_named(std::string_view element, FmiVersion version, std::string_view suffix = "") {
  if (!element.ends_with(suffix)) return std::nullopt;
  element.remove_suffix(suffix.size());
  for (const TypeName& t : kTypes) {
    const std::string_view name = version == FmiVersion::fmi2 ? t.fmi2 : t.fmi3;
    if (!name.empty() && name == element) return t.type;
  }
  return std::nullopt;
}

std::string type_list(FmiVersion version, std::string_view suffix = "") {
  std::string out;
  for (const TypeName& t : kTypes) {
    const std::string_view name = version == FmiVersion::fmi2 ? t.fmi2 : t.fmi3;
    if (!name.empty()) out += (out.empty() ? "" : ", ") + std::string(name) + std::string(suffix);
  }
  return out;
}

// Which value-reference space a variable's reference belongs to: FMI 3.0 one for all; FMI 2.0 one per
// fmi2Get function (Real; Integer and Enumeration; Boolean; String).
int reference_space(VariableType type, FmiVersion version) {
  if (version == FmiVersion::fmi3) return 0;
  switch (type) {
    case VariableType::float64:
      return 1;
    case VariableType::int32:
    case VariableType::enumeration:
      return 2;
    case VariableType::boolean:
      return 3;
    default:
      return 4;
  }
}

}  // namespace

std::string_view to_string(Causality causality) { return kCausalities[static_cast<std::size_t>(causality)]; }
std::string_view to_string(Variability variability) { return kVariabilities[static_cast<std::size_t>(variability)]; }

std::string_view type_element(VariableType type, FmiVersion version) {
  const TypeName& t = kTypes[static_cast<std::size_t>(type)];
  return version == FmiVersion::fmi2 && !t.fmi2.empty() ? t.fmi2 : t.fmi3;
}

bool is_float(VariableType type) { return type == VariableType::float32 || type == VariableType::float64; }

bool is_integer(VariableType type) {
  return static_cast<int>(type) >= static_cast<int>(VariableType::int8) &&
         static_cast<int>(type) <= static_cast<int>(VariableType::uint64);
}

std::pair<double, double> integer_limits(VariableType type, FmiVersion version) {
  const auto limits = []<typename T>(T) {
    return std::pair<double, double>{static_cast<double>(std::numeric_limits<T>::lowest()),
                                     static_cast<double>(std::numeric_limits<T>::max())};
  };
  switch (type) {
    case VariableType::int8:
      return limits(std::int8_t{});
    case VariableType::uint8:
      return limits(std::uint8_t{});
    case VariableType::int16:
      return limits(std::int16_t{});
    case VariableType::uint16:
      return limits(std::uint16_t{});
    case VariableType::uint32:
      return limits(std::uint32_t{});
    case VariableType::int64:
      return limits(std::int64_t{});
    case VariableType::uint64:
      return limits(std::uint64_t{});
    case VariableType::enumeration:
      return version == FmiVersion::fmi2 ? limits(std::int32_t{}) : limits(std::int64_t{});
    default:
      return limits(std::int32_t{});
  }
}

namespace detail {

void DescriptionReader::read_type_definitions(const tinyxml2::XMLElement& list) {
  std::map<std::string, int> names;
  for (const tinyxml2::XMLElement* e = list.FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    if (out_.type_definitions.size() >= kMaxTypeDefinitions) {
      problem(e->GetLineNum(), "more than " + std::to_string(kMaxTypeDefinitions) + " type definitions");
      return;
    }
    auto type = read_type_definition(*e);
    if (!type) continue;
    if (const auto [it, fresh] = names.emplace(type->name, type->line); !fresh) {
      problem(type->line, "type '" + type->name + "' defined twice (first at line " + std::to_string(it->second) + ")");
      continue;
    }
    out_.type_definitions.push_back(std::move(*type));
  }
}

std::optional<TypeDefinition> DescriptionReader::read_type_definition(const tinyxml2::XMLElement& e) {
  const FmiVersion version = out_.version;
  // FMI 2.0: <SimpleType name><Real .../></SimpleType>; FMI 3.0: <Float64Type name .../>.
  const tinyxml2::XMLElement* body = &e;
  if (version == FmiVersion::fmi2) {
    if (std::string_view(e.Name()) != "SimpleType") {
      problem(e.GetLineNum(), std::string("unknown element <") + e.Name() + "> in <TypeDefinitions> (SimpleType)");
      return std::nullopt;
    }
    body = e.FirstChildElement();
    while (body != nullptr && std::string_view(body->Name()) == "Annotations") body = body->NextSiblingElement();
    if (body == nullptr) {
      problem(e.GetLineNum(), "<SimpleType> without a type element (" + type_list(version) + ")");
      return std::nullopt;
    }
  }
  const auto type = type_named(body->Name(), version, version == FmiVersion::fmi2 ? "" : "Type");
  if (!type) {
    problem(body->GetLineNum(), std::string("unknown type element <") + body->Name() + "> (one of " +
                                    type_list(version, version == FmiVersion::fmi2 ? "" : "Type") + ")");
    return std::nullopt;
  }
  TypeDefinition t;
  t.type = *type;
  t.line = e.GetLineNum();
  const auto name = required(e, "name");
  if (!name) return std::nullopt;
  t.name = *name;
  t.unit = text(*body, "unit");
  t.min = number(*body, "min");
  t.max = number(*body, "max");
  if (t.type == VariableType::enumeration) read_enumeration_items(*body, t);
  return t;
}

void DescriptionReader::read_enumeration_items(const tinyxml2::XMLElement& e, TypeDefinition& type) {
  const auto [lowest, highest] = integer_limits(VariableType::enumeration, out_.version);
  for (const tinyxml2::XMLElement* item = e.FirstChildElement("Item"); item != nullptr;
       item = item->NextSiblingElement("Item")) {
    if (type.items.size() >= kMaxEnumerationItems) {
      problem(item->GetLineNum(), "more than " + std::to_string(kMaxEnumerationItems) + " items in one enumeration");
      return;
    }
    const auto name = required(*item, "name");
    const auto value = whole_number(*item, "value");
    if (!item->Attribute("value")) problem(item->GetLineNum(), "<Item> lacks the required attribute 'value'");
    if (!name || !value) continue;
    if (static_cast<double>(*value) < lowest || static_cast<double>(*value) > highest) {
      problem(item->GetLineNum(),
              "item '" + *name + "' has a value outside the range of FMI 2.0 enumerations (32 bits)");
      continue;
    }
    const bool taken = std::any_of(type.items.begin(), type.items.end(),
                                   [&](const EnumerationItem& i) { return i.name == *name || i.value == *value; });
    if (taken) {
      problem(item->GetLineNum(), "item '" + *name + "' repeats a name or value of enumeration '" + type.name + "'");
      continue;
    }
    type.items.push_back({*name, *value});
  }
  if (type.items.empty()) problem(e.GetLineNum(), "enumeration '" + type.name + "' has no <Item>");
}

void DescriptionReader::read_variables(const tinyxml2::XMLElement& list) {
  for (const tinyxml2::XMLElement* e = list.FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    if (out_.variables.size() >= kMaxVariables) {
      problem(e->GetLineNum(), "more than " + std::to_string(kMaxVariables) + " variables");
      return;
    }
    const std::string_view name = e->Name();
    if (name == "Annotations") continue;
    if (out_.version == FmiVersion::fmi2) {
      if (name == "ScalarVariable") {
        read_fmi2_variable(*e);
      } else {
        problem(e->GetLineNum(), "unknown element <" + std::string(name) + "> in <ModelVariables> (ScalarVariable)");
      }
    } else if (const auto type = type_named(name, FmiVersion::fmi3)) {
      read_fmi3_variable(*e, *type);
    } else {
      problem(e->GetLineNum(),
              "unknown variable type element <" + std::string(name) + "> (one of " + type_list(FmiVersion::fmi3) + ")");
    }
  }
}

// name, valueReference, causality, variability and description: on <ScalarVariable> (2.0) or on the
// type element (3.0). False when the variable cannot be kept.
bool DescriptionReader::read_common(const tinyxml2::XMLElement& e, Variable& v) {
  v.line = e.GetLineNum();
  const auto name = required(e, "name");
  const bool has_reference = e.Attribute("valueReference") != nullptr;
  const auto reference = unsigned_number(e, "valueReference", std::numeric_limits<std::uint32_t>::max());
  if (!has_reference)
    problem(e.GetLineNum(), std::string("<") + e.Name() + "> lacks the required attribute 'valueReference'");
  v.description = text(e, "description");
  if (const char* c = e.Attribute("causality")) {
    const auto it = std::find(kCausalities.begin(), kCausalities.end(), std::string_view(c));
    const bool known = it != kCausalities.end() && !(out_.version == FmiVersion::fmi2 && *it == "structuralParameter");
    if (known) {
      v.causality = static_cast<Causality>(it - kCausalities.begin());
    } else {
      problem(e.GetLineNum(), std::string("unknown causality \"") + c + "\"");
      return false;
    }
  }
  if (const char* value = e.Attribute("variability")) {
    const auto it = std::find(kVariabilities.begin(), kVariabilities.end(), std::string_view(value));
    if (it == kVariabilities.end()) {
      problem(e.GetLineNum(), std::string("unknown variability \"") + value + "\"");
      return false;
    }
    v.variability = static_cast<Variability>(it - kVariabilities.begin());
  }
  if (!name || !reference) return false;
  v.name = *name;
  v.value_reference = static_cast<std::uint32_t>(*reference);
  return true;
}

// declaredType, start and unit, on the type element.
void DescriptionReader::read_type_attributes(const tinyxml2::XMLElement& e, Variable& v) {
  v.declared_type = text(e, "declaredType");
  if (const char* start = e.Attribute("start")) v.start.emplace_back(start);
  v.unit = text(e, "unit");
  const TypeDefinition* declared = v.declared_type.empty() ? nullptr : out_.find_type(v.declared_type);
  if (!v.declared_type.empty() && (declared == nullptr || declared->type != v.type)) {
    problem(e.GetLineNum(), "variable '" + v.name + "': declaredType '" + v.declared_type + "' names no " +
                                std::string(type_element(v.type, out_.version)) + " type of <TypeDefinitions>");
  } else if (v.type == VariableType::enumeration && declared == nullptr) {
    problem(e.GetLineNum(), "variable '" + v.name + "': an Enumeration needs a declaredType");
  }
  v.min = number(e, "min");
  v.max = number(e, "max");
  if (declared != nullptr) {
    if (v.unit.empty()) v.unit = declared->unit;
    if (!v.min) v.min = declared->min;
    if (!v.max) v.max = declared->max;
  }
  if (v.min && v.max && *v.min > *v.max) problem(e.GetLineNum(), "variable '" + v.name + "': min is above max");
}

void DescriptionReader::read_fmi2_variable(const tinyxml2::XMLElement& e) {
  Variable v;
  const bool kept = read_common(e, v);
  const tinyxml2::XMLElement* body = e.FirstChildElement();
  while (body != nullptr && std::string_view(body->Name()) == "Annotations") body = body->NextSiblingElement();
  if (body == nullptr) {
    problem(e.GetLineNum(), "variable '" + v.name + "' has no type element (" + type_list(FmiVersion::fmi2) + ")");
    return;
  }
  const auto type = type_named(body->Name(), FmiVersion::fmi2);
  if (!type) {
    problem(body->GetLineNum(),
            std::string("unknown type element <") + body->Name() + "> (one of " + type_list(FmiVersion::fmi2) + ")");
    return;
  }
  if (!kept) return;
  v.type = *type;
  // Only a Real may be continuous: the other types default to discrete.
  if (!e.Attribute("variability") && v.type != VariableType::float64) v.variability = Variability::discrete;
  read_type_attributes(*body, v);
  add_variable(std::move(v), e.GetLineNum());
}

void DescriptionReader::read_fmi3_variable(const tinyxml2::XMLElement& e, VariableType type) {
  Variable v;
  v.type = type;
  if (!read_common(e, v)) return;
  if (!e.Attribute("variability") && !is_float(type)) v.variability = Variability::discrete;
  read_type_attributes(e, v);
  read_fmi3_children(e, v);
  const Variable base = v;
  add_variable(std::move(v), e.GetLineNum());
  for (const tinyxml2::XMLElement* a = e.FirstChildElement("Alias"); a != nullptr; a = a->NextSiblingElement("Alias")) {
    const auto name = required(*a, "name");
    if (!name) continue;
    Variable alias = base;
    alias.name = *name;
    alias.description = text(*a, "description");
    alias.alias_of = base.name;
    alias.line = a->GetLineNum();
    add_variable(std::move(alias), a->GetLineNum());
  }
}

void DescriptionReader::read_fmi3_children(const tinyxml2::XMLElement& e, Variable& v) {
  for (const tinyxml2::XMLElement* c = e.FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
    const std::string_view name = c->Name();
    if (name == "Dimension") {
      Dimension d;
      d.start = unsigned_number(*c, "start", std::numeric_limits<std::uint64_t>::max());
      if (auto vr = unsigned_number(*c, "valueReference", std::numeric_limits<std::uint32_t>::max()))
        d.value_reference = static_cast<std::uint32_t>(*vr);
      if ((c->Attribute("start") == nullptr) == (c->Attribute("valueReference") == nullptr))
        problem(c->GetLineNum(), "<Dimension> needs exactly one of 'start' and 'valueReference'");
      v.dimensions.push_back(d);
    } else if (name == "Start" && (v.type == VariableType::string || v.type == VariableType::binary)) {
      if (auto value = required(*c, "value", true)) v.start.push_back(*value);
    } else if (name != "Alias" && name != "Annotations" && name != "Item") {
      problem(c->GetLineNum(), "unknown element <" + std::string(name) + "> in variable '" + v.name + "'");
    }
  }
}

void DescriptionReader::add_variable(Variable v, int name_line) {
  if (const auto [it, fresh] = variable_lines_.emplace(v.name, name_line); !fresh) {
    problem(name_line, "variable name '" + v.name + "' used twice (first at line " + std::to_string(it->second) + ")");
    return;
  }
  if (v.alias_of.empty()) check_value_reference(v);
  out_.variables.push_back(std::move(v));
}

void DescriptionReader::check_value_reference(const Variable& v) {
  const auto key = std::pair{reference_space(v.type, out_.version), v.value_reference};
  const auto [it, fresh] = references_.emplace(key, out_.variables.size());
  if (fresh) return;
  const Variable& first = out_.variables[it->second];
  const std::string reference = "valueReference " + std::to_string(v.value_reference);
  if (out_.version == FmiVersion::fmi3) {
    problem(v.line, "variable '" + v.name + "': " + reference + " is also '" + first.name + "''s (line " +
                        std::to_string(first.line) + "); FMI 3.0 gives another name as an <Alias>");
  } else if (first.type != v.type) {
    problem(v.line, "variable '" + v.name + "' (" + std::string(type_element(v.type, out_.version)) +
                        "): " + reference + " is also '" + first.name + "''s (" +
                        std::string(type_element(first.type, out_.version)) + ", line " + std::to_string(first.line) +
                        "), which the same fmi2Get function reads");
  }
}

}  // namespace detail
}  // namespace cosmic::fmi
