// The mapping table of FMU variables and channel fields, and parameter values (cosmic/fmi_mapping.hpp).
#include "cosmic/fmi_mapping.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <vector>

namespace cosmic::fmi {
namespace {

using Range = std::pair<double, double>;

std::string range_text(Range r) { return shortest_number_text(r.first) + ".." + shortest_number_text(r.second); }

bool within(Range inner, Range outer) { return inner.first >= outer.first && inner.second <= outer.second; }

// The values an integer (or enumeration) variable may hold: its declared range, else its type's.
Range variable_range(const Variable& v, const FmuDescription& d) {
  const Range limits = integer_limits(v.type, d.version);
  return {v.min.value_or(limits.first), v.max.value_or(limits.second)};
}

Range field_range(const TypeField& field) {
  const Range limits = scalar_limits(field.type.scalar);
  return {field.minimum.value_or(limits.first), field.maximum.value_or(limits.second)};
}

const std::vector<EnumerationItem>* items_of(const Variable& v, const FmuDescription& d) {
  const TypeDefinition* t = d.find_type(v.declared_type);
  return t != nullptr ? &t->items : nullptr;
}

std::string integer_problem(const Variable& v, const FmuDescription& d, const TypeField& field, Flow flow) {
  const Range variable = variable_range(v, d);
  const Range carried = field_range(field);
  if (flow == Flow::output && !within(variable, carried)) {
    return "its values (" + range_text(variable) + ") do not all fit the field (" + range_text(carried) +
           "): declare the variable's min/max, or widen the field";
  }
  if (flow == Flow::input && !within(carried, variable)) {
    return "the field's values (" + range_text(carried) + ") do not all fit the variable (" + range_text(variable) +
           "): declare the field's range, or map a wider variable";
  }
  return {};
}

std::string enumeration_problem(const Variable& v, const FmuDescription& d, const TypeField& field, Flow flow) {
  const std::vector<EnumerationItem>* items = items_of(v, d);
  if (items == nullptr || items->empty()) return "its declared type has no items";
  const auto has_item = [&](std::int64_t value) {
    return std::any_of(items->begin(), items->end(), [&](const EnumerationItem& i) { return i.value == value; });
  };
  if (field.type.kind == FieldType::Kind::enumeration) {
    const auto& values = field.type.values;
    if (flow == Flow::output) {
      for (const auto& item : *items) {
        const bool named =
            std::any_of(values.begin(), values.end(), [&](const EnumValue& e) { return e.value == item.value; });
        if (!named) return "item " + item.name + "=" + std::to_string(item.value) + " is no value of the field";
      }
    } else {
      for (const auto& value : values)
        if (!has_item(value.value))
          return "the field's value " + value.name + "=" + std::to_string(value.value) + " is no item of the variable";
    }
    return {};
  }
  const auto [lowest, highest] =
      std::minmax_element(items->begin(), items->end(),
                          [](const EnumerationItem& a, const EnumerationItem& b) { return a.value < b.value; });
  const Range item_range{static_cast<double>(lowest->value), static_cast<double>(highest->value)};
  const Range carried = field_range(field);
  if (flow == Flow::output && !within(item_range, carried))
    return "its items (" + range_text(item_range) + ") do not all fit the field (" + range_text(carried) + ")";
  if (flow == Flow::input && !within(carried, item_range))
    return "the field's values (" + range_text(carried) + ") go beyond the items (" + range_text(item_range) +
           "): declare the field's range";
  return {};
}

template <typename T>
std::optional<T> parsed_number(std::string_view s) {
  T value{};
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

}  // namespace

std::string mapping_problem(const Variable& v, const FmuDescription& d, const TypeField& field, Flow flow) {
  if (!v.dimensions.empty()) return "it is an array (FMI 3.0 <Dimension>); only scalar variables are mapped";
  const FieldType& t = field.type;
  if (t.kind == FieldType::Kind::array || t.kind == FieldType::Kind::sequence || t.kind == FieldType::Kind::record)
    return "the field is " + describe(t) + ": map a number, bool, enumeration or string field";
  const bool scalar = t.kind == FieldType::Kind::scalar;
  const bool field_float = scalar && (t.scalar == ScalarKind::float32 || t.scalar == ScalarKind::float64);
  const bool field_integer = scalar && cosmic::is_integer(t.scalar);
  const std::string kinds = std::string(type_element(v.type, d.version)) + " carries ";
  if (is_float(v.type)) {
    return field_float || field_integer ? std::string() : kinds + "float and integer fields, not " + describe(t);
  }
  if (is_integer(v.type)) {
    if (field_float)
      return flow == Flow::output ? std::string()
                                  : "a float field's values are not whole numbers: map it to a float variable";
    return field_integer ? integer_problem(v, d, field, flow) : kinds + "integer and float fields, not " + describe(t);
  }
  switch (v.type) {
    case VariableType::boolean:
      return scalar && t.scalar == ScalarKind::boolean ? std::string() : kinds + "bool fields, not " + describe(t);
    case VariableType::enumeration:
      return t.kind == FieldType::Kind::enumeration || field_integer
                 ? enumeration_problem(v, d, field, flow)
                 : kinds + "enumeration and integer fields, not " + describe(t);
    case VariableType::string:
      return t.kind == FieldType::Kind::string ? std::string() : kinds + "string fields, not " + describe(t);
    default:
      return std::string(type_element(v.type, d.version)) +
             " variables are not mapped (numbers, Booleans, enumerations and strings are)";
  }
}

std::string parameter_problem(const Variable& v, const FmuDescription& d, std::string_view text) {
  if (!v.dimensions.empty()) return "an array parameter is not set from the configuration";
  if (is_float(v.type)) {
    const auto value = parsed_number<double>(text);
    if (!value || !std::isfinite(*value)) return "'" + std::string(text) + "' is not a number";
    if ((v.min && *value < *v.min) || (v.max && *value > *v.max))
      return "'" + std::string(text) + "' is outside the variable's range " +
             range_text({v.min.value_or(-INFINITY), v.max.value_or(INFINITY)});
    return {};
  }
  if (is_integer(v.type)) {
    const Range range = variable_range(v, d);
    const auto as_signed = parsed_number<std::int64_t>(text);
    const auto as_unsigned = parsed_number<std::uint64_t>(text);
    if (!as_signed && !as_unsigned) return "'" + std::string(text) + "' is not a whole number";
    const double value = as_signed ? static_cast<double>(*as_signed) : static_cast<double>(*as_unsigned);
    if (value < range.first || value > range.second)
      return "'" + std::string(text) + "' is outside the variable's range " + range_text(range);
    return {};
  }
  switch (v.type) {
    case VariableType::boolean:
      return text == "true" || text == "false" ? std::string() : "'" + std::string(text) + "' is not true or false";
    case VariableType::enumeration: {
      const std::vector<EnumerationItem>* items = items_of(v, d);
      const auto value = parsed_number<std::int64_t>(text);
      const bool known = items != nullptr && std::any_of(items->begin(), items->end(), [&](const EnumerationItem& i) {
                           return i.name == text || (value && i.value == *value);
                         });
      if (known) return {};
      std::string names;
      if (items != nullptr)
        for (const auto& i : *items) names += (names.empty() ? "" : ", ") + i.name + "=" + std::to_string(i.value);
      return "'" + std::string(text) + "' is no item of the enumeration (" + names + ")";
    }
    case VariableType::string:
      return {};
    default:
      return std::string(type_element(v.type, d.version)) + " parameters are not set from the configuration";
  }
}

}  // namespace cosmic::fmi

namespace cosmic::fmi {

Result<VariableValue> parse_value(const Variable& v, const FmuDescription& d, std::string_view text) {
  if (std::string why = parameter_problem(v, d, text); !why.empty()) return Error{std::move(why)};
  if (is_float(v.type)) return VariableValue(*parsed_number<double>(text));
  if (is_integer(v.type)) {
    const bool is_unsigned = v.type == VariableType::uint8 || v.type == VariableType::uint16 ||
                             v.type == VariableType::uint32 || v.type == VariableType::uint64;
    if (is_unsigned) return VariableValue(*parsed_number<std::uint64_t>(text));
    return VariableValue(*parsed_number<std::int64_t>(text));
  }
  switch (v.type) {
    case VariableType::boolean:
      return VariableValue(text == "true");
    case VariableType::enumeration: {
      if (const auto value = parsed_number<std::int64_t>(text)) return VariableValue(*value);
      for (const auto& item : *items_of(v, d))
        if (item.name == text) return VariableValue(item.value);
      break;
    }
    default:
      break;
  }
  return VariableValue(std::string(text));
}

}  // namespace cosmic::fmi
