// Values of FMU variables as the runner holds them, and their conversion to and from the fields of
// typed channels by the mapping table (docs/fmu.md; cosmic/fmi_mapping.hpp checks at load that a
// variable may carry a field, these convert at run time).
//
// Pure functions; no I/O, never throw; any thread.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "cosmic/channel_type.hpp"
#include "cosmic/compact_layout.hpp"
#include "cosmic/fmi_description.hpp"
#include "cosmic/result.hpp"

namespace cosmic::fmi {

// Float types as double, signed integers and enumerations as int64, unsigned integers as uint64,
// Boolean as bool, String as text.
using VariableValue = std::variant<double, std::int64_t, std::uint64_t, bool, std::string>;

// A zero value of the variable's type (0, false, "").
VariableValue zero_value(const Variable& variable);
// `text` (a parameter as written in the configuration: a number, true/false, an enumeration item's
// name or value, any text) as a value of `variable`'s type; why not, as parameter_problem() says.
Result<VariableValue> parse_value(const Variable& variable, const FmuDescription& description, std::string_view text);
std::string to_string(const VariableValue& value);

// A field's value in the compact layout's terms: a scalar (an enumeration's underlying integer) in
// the ScalarValue member its kind uses, or a string's bytes.
struct FieldValue {
  ScalarValue scalar;
  std::string text;
  bool present = true;  // false: a conditional field its selector does not select (read() only)
};

// The field's value as the input variable takes it (float fields and integer fields to floats,
// integer and enumeration fields to integers, bool, string). The configuration checked the pair
// against the field's declared range, which events need not keep (a DBC signal's raw values, another
// publisher): a whole number beyond the variable's range (declared, else its type's) is saturated
// and `clipped` set; a value of an Enumeration variable that is none of its items gives nullopt
// (the caller keeps the variable as it was and counts the event as undecodable).
std::optional<VariableValue> to_variable(const Variable& variable, const FmuDescription& description,
                                         const TypeField& field, const FieldValue& value, bool& clipped);

// The output variable's value as the field holds it. A float into an integer field is rounded to
// nearest; a value the field cannot hold (beyond its kind's or declared range, NaN, a string longer
// than its bound) is saturated (a string cut at its bound) and `clipped` set.
FieldValue to_field(const TypeField& field, const VariableValue& value, bool& clipped);

}  // namespace cosmic::fmi
