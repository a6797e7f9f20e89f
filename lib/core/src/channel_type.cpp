#include "cosmic/channel_type.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <set>

#include "cosmic/lcm_types.hpp"

namespace cosmic {

bool operator==(const TypeSource& a, const TypeSource& b) {
  const bool same_lcm =
      a.lcm_file == b.lcm_file || (a.lcm_file && b.lcm_file && a.lcm_file->structs == b.lcm_file->structs);
  return a.format == b.format && a.file == b.file && a.name == b.name && a.max_length == b.max_length &&
         a.dbc_message == b.dbc_message && same_lcm && a.type_path == b.type_path && a.appendable == b.appendable &&
         a.e2e == b.e2e;
}

namespace {

constexpr std::array<std::string_view, 11> kScalarNames = {"bool",   "int8",   "int16",  "int32",   "int64",  "uint8",
                                                           "uint16", "uint32", "uint64", "float32", "float64"};

std::string number_text(double value) { return shortest_number_text(value); }

std::string child(const std::string& where, const std::string& name) {
  return where.empty() ? name : where + "." + name;
}

std::uint64_t saturating_multiply(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return std::numeric_limits<std::uint64_t>::max();
  return a * b;
}

// The scalars one largest value of `type` holds (arrays and sequences expanded), saturating.
std::uint64_t flattened_scalars(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
    case FieldType::Kind::enumeration:
    case FieldType::Kind::string:
      return 1;
    case FieldType::Kind::array:
    case FieldType::Kind::sequence:
      return type.element.size() == 1 ? saturating_multiply(type.bound, flattened_scalars(type.element[0])) : 1;
    case FieldType::Kind::record: {
      std::uint64_t sum = 0;
      for (const TypeField& f : type.fields) sum = std::min(sum + flattened_scalars(f.type), kMaxFlattenedScalars + 1);
      return sum;
    }
  }
  return 1;
}

// The scalar a numeric type's values are: its own, or its (nested) elements'.
std::optional<ScalarKind> numeric_kind(const FieldType& type) {
  if (type.kind == FieldType::Kind::scalar) return type.scalar;
  if ((type.kind == FieldType::Kind::array || type.kind == FieldType::Kind::sequence) && type.element.size() == 1)
    return numeric_kind(type.element[0]);
  return std::nullopt;
}

class TypeChecker {
 public:
  std::vector<TypeProblem> problems;

  void record(const std::vector<TypeField>& fields, const std::string& where, std::size_t depth) {
    if (fields.empty()) add(where, "a record needs at least one field");
    if (fields.size() > kMaxRecordFields) {
      add(where, std::to_string(fields.size()) + " fields, at most " + std::to_string(kMaxRecordFields));
    }
    std::set<std::string> names;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const TypeField& f = fields[i];
      // By name, but by position where the name does not tell it apart (none, or given twice).
      const bool twice = names.count(f.name) != 0;
      const std::string at =
          f.name.empty() || twice ? child(where, "fields[" + std::to_string(i) + "]") : child(where, f.name);
      if (!valid_field_name(f.name)) {
        add(at, "field name '" + f.name + "' is not [A-Za-z][A-Za-z0-9_]* of at most 64 characters");
      } else if (!names.insert(f.name).second) {
        add(at, "field '" + f.name + "' defined twice");
      }
      field_type(f.type, at, depth);
      unit_and_range(f, at);
      if (f.present_when) presence(fields, i, at);
    }
  }

 private:
  void add(const std::string& where, std::string what) { problems.push_back(TypeProblem{where, std::move(what)}); }

  void field_type(const FieldType& type, const std::string& where, std::size_t depth) {
    if (depth >= kMaxTypeDepth) {
      add(where, "nested more than " + std::to_string(kMaxTypeDepth) + " levels deep");
      return;
    }
    const bool has_element = type.kind == FieldType::Kind::array || type.kind == FieldType::Kind::sequence;
    if (has_element != (type.element.size() == 1) || type.element.size() > 1) {
      add(where, has_element ? "needs exactly one element type" : "only arrays and sequences have an element type");
    }
    if (type.kind != FieldType::Kind::record && !type.fields.empty()) add(where, "only records have fields");
    if (type.kind != FieldType::Kind::enumeration && !type.values.empty()) add(where, "only enumerations have values");
    switch (type.kind) {
      case FieldType::Kind::scalar:
        break;
      case FieldType::Kind::enumeration:
        enumeration(type, where);
        break;
      case FieldType::Kind::string:
      case FieldType::Kind::array:
      case FieldType::Kind::sequence:
        if (type.bound < 1 || type.bound > kMaxTypeBound) {
          add(where, std::string(type.kind == FieldType::Kind::array ? "length " : "bound ") +
                         std::to_string(type.bound) + " is not 1.." + std::to_string(kMaxTypeBound));
        }
        if (has_element && type.element.size() == 1) field_type(type.element[0], child(where, "element"), depth + 1);
        break;
      case FieldType::Kind::record:
        record(type.fields, where, depth + 1);
        break;
    }
  }

  void enumeration(const FieldType& type, const std::string& where) {
    if (!is_integer(type.scalar)) {
      add(where, "an enumeration's values are integers, not " + std::string(scalar_name(type.scalar)));
      return;
    }
    if (type.values.empty() || type.values.size() > kMaxEnumValues) {
      add(where, "an enumeration has 1.." + std::to_string(kMaxEnumValues) + " named values");
    }
    const auto [lowest, highest] = scalar_limits(type.scalar);
    std::set<std::string> names;
    std::set<std::int64_t> numbers;
    for (const EnumValue& v : type.values) {
      if (!valid_field_name(v.name)) add(where, "value name '" + v.name + "' is not [A-Za-z][A-Za-z0-9_]*");
      if (!names.insert(v.name).second) add(where, "value name '" + v.name + "' defined twice");
      if (!numbers.insert(v.value).second) add(where, "value " + std::to_string(v.value) + " named twice");
      if (static_cast<double>(v.value) < lowest || static_cast<double>(v.value) > highest) {
        add(where, "value " + v.name + " = " + std::to_string(v.value) + " does not fit " +
                       std::string(scalar_name(type.scalar)));
      }
    }
  }

  void presence(const std::vector<TypeField>& fields, std::size_t index, const std::string& where) {
    const FieldPresence& when = *fields[index].present_when;
    const auto selector = std::find_if(fields.begin(), fields.begin() + static_cast<std::ptrdiff_t>(index),
                                       [&](const TypeField& f) { return f.name == when.selector; });
    if (selector == fields.begin() + static_cast<std::ptrdiff_t>(index)) {
      add(where, "its selector '" + when.selector + "' is not a field declared before it in the same record");
      return;
    }
    const FieldType& type = selector->type;
    const bool integral =
        (type.kind == FieldType::Kind::scalar || type.kind == FieldType::Kind::enumeration) && is_integer(type.scalar);
    if (!integral || selector->present_when) {
      add(where, "its selector '" + when.selector + "' is not an always present integer or enumeration field");
      return;
    }
    const auto [lowest, highest] = scalar_limits(type.scalar);
    if (static_cast<double>(when.value) < lowest || static_cast<double>(when.value) > highest) {
      add(where, "its selector value " + std::to_string(when.value) + " does not fit " +
                     std::string(scalar_name(type.scalar)));
    }
  }

  void unit_and_range(const TypeField& f, const std::string& where) {
    const std::optional<ScalarKind> kind = numeric_kind(f.type);
    if (!kind) {
      if (!f.unit.empty() || f.minimum || f.maximum) add(where, "a unit and a range belong to numeric fields only");
      return;
    }
    const auto [lowest, highest] = scalar_limits(*kind);
    for (const auto& [bound, word] : {std::pair{f.minimum, "min"}, std::pair{f.maximum, "max"}}) {
      if (!bound) continue;
      if (!std::isfinite(*bound) || *bound < lowest || *bound > highest) {
        add(where, std::string(word) + " " + number_text(*bound) + " is outside what " +
                       std::string(scalar_name(*kind)) + " holds (" + number_text(lowest) + ".." +
                       number_text(highest) + ")");
      }
    }
    if (f.minimum && f.maximum && *f.minimum > *f.maximum) {
      add(where, "min " + number_text(*f.minimum) + " is above max " + number_text(*f.maximum));
    }
  }
};

}  // namespace

std::string_view scalar_name(ScalarKind kind) { return kScalarNames.at(static_cast<std::size_t>(kind)); }

std::optional<ScalarKind> scalar_kind(std::string_view name) {
  const auto it = std::find(kScalarNames.begin(), kScalarNames.end(), name);
  if (it == kScalarNames.end()) return std::nullopt;
  return static_cast<ScalarKind>(it - kScalarNames.begin());
}

bool is_integer(ScalarKind kind) {
  return kind != ScalarKind::boolean && kind != ScalarKind::float32 && kind != ScalarKind::float64;
}

bool is_signed_integer(ScalarKind kind) {
  return kind == ScalarKind::int8 || kind == ScalarKind::int16 || kind == ScalarKind::int32 ||
         kind == ScalarKind::int64;
}

std::pair<double, double> scalar_limits(ScalarKind kind) {
  switch (kind) {
    case ScalarKind::boolean:
      return {0, 1};
    case ScalarKind::int8:
      return {-128, 127};
    case ScalarKind::int16:
      return {-32768, 32767};
    case ScalarKind::int32:
      return {-2147483648.0, 2147483647.0};
    case ScalarKind::int64:
      return {-9223372036854775808.0, 9223372036854775807.0};
    case ScalarKind::uint8:
      return {0, 255};
    case ScalarKind::uint16:
      return {0, 65535};
    case ScalarKind::uint32:
      return {0, 4294967295.0};
    case ScalarKind::uint64:
      return {0, 18446744073709551615.0};
    case ScalarKind::float32:
      return {-std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
    case ScalarKind::float64:
      return {-std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
  }
  return {0, 0};
}

bool valid_field_name(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  const auto alpha = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); };
  if (!alpha(name.front())) return false;
  return std::all_of(name.begin(), name.end(), [&](char c) { return alpha(c) || (c >= '0' && c <= '9') || c == '_'; });
}

std::string shortest_number_text(double value) {
  std::array<char, 32> buffer{};
  const auto [end, error] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return error == std::errc() ? std::string(buffer.data(), end) : std::string("?");
}

bool is_numeric(const FieldType& type) { return numeric_kind(type).has_value(); }

std::vector<TypeProblem> check_type(const ChannelType& type) {
  TypeChecker checker;
  checker.record(type.fields, "", 0);
  if (checker.problems.empty()) {
    FieldType whole;
    whole.kind = FieldType::Kind::record;
    whole.fields = type.fields;
    if (flattened_scalars(whole) > kMaxFlattenedScalars) {
      checker.problems.push_back(
          TypeProblem{"", "its largest value holds more than " + std::to_string(kMaxFlattenedScalars) + " scalars"});
    }
  }
  return checker.problems;
}

std::string describe(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
      return std::string(scalar_name(type.scalar));
    case FieldType::Kind::enumeration: {
      std::string out = "enum " + std::string(scalar_name(type.scalar)) + " {";
      for (std::size_t i = 0; i < type.values.size(); ++i) {
        out += (i ? ", " : "") + type.values[i].name + "=" + std::to_string(type.values[i].value);
      }
      return out + "}";
    }
    case FieldType::Kind::string:
      return "string<=" + std::to_string(type.bound) + ">";
    case FieldType::Kind::array:
      return (type.element.empty() ? std::string("?") : describe(type.element[0])) + "[" + std::to_string(type.bound) +
             "]";
    case FieldType::Kind::sequence:
      return "sequence<" + (type.element.empty() ? std::string("?") : describe(type.element[0])) + ", " +
             std::to_string(type.bound) + ">";
    case FieldType::Kind::record: {
      ChannelType inner;
      inner.fields = type.fields;
      return describe(inner);
    }
  }
  return "?";
}

std::string describe(const TypeField& f) {
  std::string out = f.name + ": " + describe(f.type);
  if (!f.unit.empty() || f.minimum || f.maximum) {
    std::string extra = f.unit;
    if (f.minimum || f.maximum) {
      extra += (extra.empty() ? "" : ", ") + (f.minimum ? number_text(*f.minimum) : std::string()) + ".." +
               (f.maximum ? number_text(*f.maximum) : std::string());
    }
    out += " [" + extra + "]";
  }
  if (f.present_when) out += " when " + f.present_when->selector + "=" + std::to_string(f.present_when->value);
  return out;
}

std::string describe(const ChannelType& type) {
  std::string out = "{";
  for (std::size_t i = 0; i < type.fields.size(); ++i) out += (i ? ", " : "") + describe(type.fields[i]);
  return out + "}";
}

}  // namespace cosmic
