// Variable values and their conversion to and from channel fields (cosmic/fmi_values.hpp).
#include "cosmic/fmi_values.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cosmic::fmi {
namespace {

bool is_unsigned(VariableType t) {
  return t == VariableType::uint8 || t == VariableType::uint16 || t == VariableType::uint32 ||
         t == VariableType::uint64;
}

// The field's declared range, else its kind's.
std::pair<double, double> field_limits(const TypeField& field) {
  const auto limits = scalar_limits(field.type.scalar);
  return {field.minimum.value_or(limits.first), field.maximum.value_or(limits.second)};
}

// A double within `range`, rounded when the field is an integer; clipped set when it was not.
ScalarValue scalar_from_double(const TypeField& field, double value, bool& clipped) {
  const ScalarKind kind = field.type.scalar;
  const auto [lowest, highest] = field_limits(field);
  if (std::isnan(value)) {
    clipped = true;
    value = 0.0;
  }
  if (cosmic::is_integer(kind)) value = std::nearbyint(value);
  if (value < lowest || value > highest) clipped = true;
  value = std::clamp(value, lowest, highest);
  ScalarValue out;
  if (kind == ScalarKind::float32 || kind == ScalarKind::float64) {
    out.real = value;
  } else if (is_signed_integer(kind)) {
    // 2^63 as a double is beyond int64: the clamp to the kind's limit can land there.
    out.integer = value >= 0x1p63 ? std::numeric_limits<std::int64_t>::max() : static_cast<std::int64_t>(value);
  } else {
    out.unsigned_integer =
        value >= 0x1p64 ? std::numeric_limits<std::uint64_t>::max() : static_cast<std::uint64_t>(value);
  }
  return out;
}

// A whole number of the variable into an integer field; the configuration checked that every value
// of the variable fits, the check here keeps a misbehaving FMU's value from wrapping.
ScalarValue scalar_from_integer(const TypeField& field, std::int64_t signed_value, std::uint64_t unsigned_value,
                                bool from_unsigned, bool& clipped) {
  const ScalarKind kind = field.type.scalar;
  if (!cosmic::is_integer(kind)) {
    return scalar_from_double(
        field, from_unsigned ? static_cast<double>(unsigned_value) : static_cast<double>(signed_value), clipped);
  }
  const auto [lowest, highest] = field_limits(field);
  ScalarValue out;
  if (is_signed_integer(kind)) {
    std::int64_t v = signed_value;
    if (from_unsigned)
      v = unsigned_value > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())
              ? std::numeric_limits<std::int64_t>::max()
              : static_cast<std::int64_t>(unsigned_value);
    const auto low = static_cast<std::int64_t>(std::max(lowest, -0x1p63));
    const std::int64_t high =
        highest >= 0x1p63 ? std::numeric_limits<std::int64_t>::max() : static_cast<std::int64_t>(highest);
    if (v < low || v > high) clipped = true;
    out.integer = std::clamp(v, low, high);
  } else {
    std::uint64_t v =
        from_unsigned ? unsigned_value : (signed_value < 0 ? 0 : static_cast<std::uint64_t>(signed_value));
    if (!from_unsigned && signed_value < 0) clipped = true;
    const auto low = static_cast<std::uint64_t>(std::max(lowest, 0.0));
    const std::uint64_t high =
        highest >= 0x1p64 ? std::numeric_limits<std::uint64_t>::max() : static_cast<std::uint64_t>(highest);
    if (v < low || v > high) clipped = true;
    out.unsigned_integer = std::clamp(v, low, high);
  }
  return out;
}

}  // namespace

VariableValue zero_value(const Variable& v) {
  if (is_float(v.type)) return 0.0;
  if (is_unsigned(v.type)) return std::uint64_t{0};
  switch (v.type) {
    case VariableType::boolean:
      return false;
    case VariableType::string:
      return std::string();
    default:
      return std::int64_t{0};
  }
}

std::string to_string(const VariableValue& value) {
  struct Text {
    std::string operator()(double v) const { return shortest_number_text(v); }
    std::string operator()(std::int64_t v) const { return std::to_string(v); }
    std::string operator()(std::uint64_t v) const { return std::to_string(v); }
    std::string operator()(bool v) const { return v ? "true" : "false"; }
    std::string operator()(const std::string& v) const { return "\"" + v + "\""; }
  };
  return std::visit(Text{}, value);
}

std::optional<VariableValue> to_variable(const Variable& v, const FmuDescription& d, const TypeField& field,
                                         const FieldValue& value, bool& clipped) {
  if (field.type.kind == FieldType::Kind::string) return VariableValue(value.text);
  const ScalarKind kind = field.type.scalar;
  if (is_float(v.type)) return VariableValue(scalar_as_double(kind, value.scalar));
  if (v.type == VariableType::boolean) return VariableValue(value.scalar.unsigned_integer != 0);
  // Integers and enumerations: the configuration let only integer (and enumeration) fields through.
  const bool negative = is_signed_integer(kind) && value.scalar.integer < 0;
  if (v.type == VariableType::enumeration) {
    const TypeDefinition* t = d.find_type(v.declared_type);
    const std::int64_t n =
        is_signed_integer(kind) ? value.scalar.integer : static_cast<std::int64_t>(value.scalar.unsigned_integer);
    const bool item = t != nullptr && std::any_of(t->items.begin(), t->items.end(),
                                                  [&](const EnumerationItem& i) { return i.value == n; });
    if (!item || (!is_signed_integer(kind) && value.scalar.unsigned_integer > 0x7fffffffffffffffull))
      return std::nullopt;
    return VariableValue(n);
  }
  const auto limits = integer_limits(v.type, d.version);
  const double lowest = std::max(v.min.value_or(limits.first), limits.first);
  const double highest = std::min(v.max.value_or(limits.second), limits.second);
  if (is_unsigned(v.type)) {
    std::uint64_t n = negative                  ? 0
                      : is_signed_integer(kind) ? static_cast<std::uint64_t>(value.scalar.integer)
                                                : value.scalar.unsigned_integer;
    const auto low = static_cast<std::uint64_t>(std::max(lowest, 0.0));
    const std::uint64_t high = highest >= 0x1p64 ? ~std::uint64_t{0} : static_cast<std::uint64_t>(highest);
    if (negative || n < low || n > high) clipped = true;
    return VariableValue(std::clamp(n, low, high));
  }
  std::int64_t n = is_signed_integer(kind) ? value.scalar.integer
                   : value.scalar.unsigned_integer > 0x7fffffffffffffffull
                       ? std::numeric_limits<std::int64_t>::max()
                       : static_cast<std::int64_t>(value.scalar.unsigned_integer);
  if (!is_signed_integer(kind) && value.scalar.unsigned_integer > 0x7fffffffffffffffull) clipped = true;
  const auto low = static_cast<std::int64_t>(std::max(lowest, -0x1p63));
  const std::int64_t high =
      highest >= 0x1p63 ? std::numeric_limits<std::int64_t>::max() : static_cast<std::int64_t>(highest);
  if (n < low || n > high) clipped = true;
  return VariableValue(std::clamp(n, low, high));
}

FieldValue to_field(const TypeField& field, const VariableValue& value, bool& clipped) {
  FieldValue out;
  if (field.type.kind == FieldType::Kind::string) {
    if (const auto* text = std::get_if<std::string>(&value)) {
      out.text = text->size() > field.type.bound ? text->substr(0, field.type.bound) : *text;
      if (text->size() > field.type.bound) clipped = true;
    }
    return out;
  }
  if (field.type.scalar == ScalarKind::boolean) {
    if (const auto* flag = std::get_if<bool>(&value)) out.scalar.unsigned_integer = *flag ? 1 : 0;
    return out;
  }
  if (const auto* real = std::get_if<double>(&value)) {
    out.scalar = scalar_from_double(field, *real, clipped);
  } else if (const auto* whole = std::get_if<std::int64_t>(&value)) {
    out.scalar = scalar_from_integer(field, *whole, 0, false, clipped);
  } else if (const auto* natural = std::get_if<std::uint64_t>(&value)) {
    out.scalar = scalar_from_integer(field, 0, *natural, true, clipped);
  }
  return out;
}

}  // namespace cosmic::fmi
