// A typed channel's contents from a DBC message (cosmic/dbc_type.hpp).
#include "cosmic/dbc_type.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <utility>

#include "cosmic/dbc_codec.hpp"

namespace cosmic {
namespace {

constexpr double kExactIntegers = 9007199254740992.0;  // 2^53: doubles are exact integers below it

bool whole(double value) { return std::fabs(value) < kExactIntegers && std::floor(value) == value; }

bool declares_range(const DbcSignal& s) { return s.minimum != 0.0 || s.maximum != 0.0; }

// The smallest integer kind holding [lowest, highest]; nullopt beyond 64 bits.
std::optional<ScalarKind> smallest_integer(double lowest, double highest) {
  static constexpr std::array kUnsigned{ScalarKind::uint8, ScalarKind::uint16, ScalarKind::uint32, ScalarKind::uint64};
  static constexpr std::array kSigned{ScalarKind::int8, ScalarKind::int16, ScalarKind::int32, ScalarKind::int64};
  for (const ScalarKind kind : lowest >= 0.0 ? kUnsigned : kSigned) {
    const auto [low, high] = scalar_limits(kind);
    if (lowest >= low && highest <= high) return kind;
  }
  return std::nullopt;
}

// The raw range of an integer signal as doubles (exact for 64-bit ends up to rounding).
std::pair<double, double> raw_range(const DbcSignal& s) {
  if (!s.is_signed) return {0.0, std::ldexp(1.0, static_cast<int>(s.size)) - 1.0};
  const double half = std::ldexp(1.0, static_cast<int>(s.size) - 1);
  return {-half, half - 1.0};
}

FieldType scalar(ScalarKind kind) {
  FieldType type;
  type.kind = FieldType::Kind::scalar;
  type.scalar = kind;
  return type;
}

FieldType enumeration(const DbcSignal& s) {
  auto [lowest, highest] = raw_range(s);
  for (const DbcValueName& v : s.value_names) {
    lowest = std::min(lowest, static_cast<double>(v.value));
    highest = std::max(highest, static_cast<double>(v.value));
  }
  FieldType type = scalar(smallest_integer(lowest, highest).value_or(ScalarKind::int64));
  type.kind = FieldType::Kind::enumeration;
  std::set<std::string> taken;
  for (const DbcValueName& v : s.value_names) {
    std::string name = dbc_value_identifier(v.name, v.value);
    if (!taken.insert(name).second) {
      name += "_" + std::to_string(v.value < 0 ? -v.value : v.value);
      taken.insert(name);
    }
    type.values.push_back(EnumValue{std::move(name), v.value});
  }
  return type;
}

std::optional<FieldType> whole_number(const DbcSignal& s) {
  if (!whole(s.factor) || !whole(s.offset)) return std::nullopt;
  const auto [raw_low, raw_high] = raw_range(s);
  double lowest = std::min(raw_low * s.factor + s.offset, raw_high * s.factor + s.offset);
  double highest = std::max(raw_low * s.factor + s.offset, raw_high * s.factor + s.offset);
  if (declares_range(s)) {
    lowest = std::min(lowest, s.minimum);
    highest = std::max(highest, s.maximum);
  }
  const auto kind = smallest_integer(lowest, highest);
  if (!kind) return std::nullopt;
  return scalar(*kind);
}

DbcError at(const DbcSignal& s, std::string message) { return DbcError{s.line, s.column, std::move(message)}; }

using BitMask = std::array<std::uint8_t, 64>;  // the bits of a CAN FD frame's data

BitMask bits_of(const DbcSignal& s) {
  BitMask mask{};
  dbc_write_bits(s, ~std::uint64_t{0}, mask);
  return mask;
}

bool multiplexed(const DbcSignal& s) {
  return s.multiplex == DbcMultiplex::multiplexed || s.multiplex == DbcMultiplex::multiplexed_multiplexor;
}

// Two signals one frame can carry together (not two multiplexed ones of different switch values)
// must not share a bit: packing one would overwrite the other.
std::optional<DbcError> overlap(const DbcMessage& message) {
  std::vector<BitMask> masks;
  masks.reserve(message.signals.size());
  for (const DbcSignal& s : message.signals) masks.push_back(bits_of(s));
  for (std::size_t a = 0; a < masks.size(); ++a) {
    for (std::size_t b = 0; b < a; ++b) {
      const DbcSignal& x = message.signals[a];
      const DbcSignal& y = message.signals[b];
      if (multiplexed(x) && multiplexed(y) && x.multiplex_value != y.multiplex_value) continue;
      for (std::size_t i = 0; i < masks[a].size(); ++i) {
        if ((masks[a][i] & masks[b][i]) == 0) continue;
        return at(x, "signal " + quote_value(x.name) + " shares bits of byte " + std::to_string(i) + " with signal " +
                         quote_value(y.name) + ", which the same frame carries");
      }
    }
  }
  return std::nullopt;
}

// The switch field's value when its raw value is `raw`: raw for an enumeration (raw values), else
// raw * factor + offset (whole: channel_type_from_dbc refuses another scaling).
std::int64_t selector_value(const DbcSignal& selector, std::uint32_t raw) {
  if (!selector.value_names.empty()) return raw;
  return static_cast<std::int64_t>(raw) * static_cast<std::int64_t>(selector.factor) +
         static_cast<std::int64_t>(selector.offset);
}

}  // namespace

FieldType dbc_field_type(const DbcSignal& s) {
  const bool unscaled = s.factor == 1.0 && s.offset == 0.0;
  if (s.value_type == DbcValueType::float32) return scalar(unscaled ? ScalarKind::float32 : ScalarKind::float64);
  if (s.value_type == DbcValueType::float64) return scalar(ScalarKind::float64);
  if (!s.value_names.empty()) return enumeration(s);
  const bool flag_range = !declares_range(s) || (s.minimum >= 0.0 && s.maximum <= 1.0);
  if (s.size == 1 && !s.is_signed && unscaled && flag_range) return scalar(ScalarKind::boolean);
  return whole_number(s).value_or(scalar(ScalarKind::float64));
}

std::string dbc_value_identifier(std::string_view description, std::int64_t value) {
  std::string name;
  for (const char c : description) {
    const bool keep = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
    if (keep) {
      name += c;
    } else if (!name.empty() && name.back() != '_') {
      name += '_';
    }
  }
  while (!name.empty() && name.back() == '_') name.pop_back();
  if (name.empty()) return "v" + std::to_string(value < 0 ? -value : value);
  if (!((name.front() >= 'A' && name.front() <= 'Z') || (name.front() >= 'a' && name.front() <= 'z')))
    name = "v" + name;
  if (name.size() > 64) name.resize(64);
  while (name.back() == '_') name.pop_back();
  return name;
}

DbcChannelType channel_type_from_dbc(const DbcMessage& message) {
  DbcChannelType out;
  if (message.signals.empty()) {
    out.errors.push_back(DbcError{message.line, message.column,
                                  "message " + quote_value(message.name) + " has no signals to make fields of"});
    return out;
  }
  if (message.signals.size() > kMaxRecordFields) {
    out.errors.push_back(DbcError{message.line, message.column,
                                  "message " + quote_value(message.name) + " has " +
                                      std::to_string(message.signals.size()) + " signals; a type has at most " +
                                      std::to_string(kMaxRecordFields) + " fields"});
    return out;
  }
  if (const auto shared = overlap(message)) {
    out.errors.push_back(*shared);
    return out;
  }
  const DbcSignal* selector = dbc_multiplexor(message);
  if (selector != nullptr && dbc_field_type(*selector).kind == FieldType::Kind::scalar &&
      !is_integer(dbc_field_type(*selector).scalar) && dbc_field_type(*selector).scalar != ScalarKind::boolean) {
    out.errors.push_back(at(*selector, "multiplexor switch " + quote_value(selector->name) +
                                           " has a scaling that is not whole, so its values are not the raw "
                                           "values its multiplexed signals name"));
    return out;
  }
  for (const DbcSignal& s : message.signals) {
    if (!valid_field_name(s.name)) {
      out.errors.push_back(at(s, "signal name " + quote_value(s.name) +
                                     " is not a field name ([A-Za-z][A-Za-z0-9_]*, at most 64 characters)"));
      continue;
    }
    if (s.multiplex == DbcMultiplex::multiplexed_multiplexor) {
      out.errors.push_back(at(s, "signal " + quote_value(s.name) +
                                     " is itself a multiplexor inside a multiplexed frame (extended multiplexing), "
                                     "which typed channels do not decode"));
      continue;
    }
    TypeField field;
    field.name = s.name;
    field.type = dbc_field_type(s);
    if (&s == selector && field.type.kind == FieldType::Kind::scalar && field.type.scalar == ScalarKind::boolean) {
      field.type.scalar = ScalarKind::uint8;  // a one-bit switch: a selector is an integer
    }
    if (field.type.kind == FieldType::Kind::scalar) {
      field.unit = s.unit;
      if (declares_range(s)) {
        field.minimum = s.minimum;
        field.maximum = s.maximum;
      }
    }
    if (s.multiplex == DbcMultiplex::multiplexed && selector != nullptr) {
      field.present_when = FieldPresence{selector->name, selector_value(*selector, s.multiplex_value)};
    }
    out.type.fields.push_back(std::move(field));
  }
  if (!out.errors.empty()) return out;
  for (const TypeProblem& problem : check_type(out.type)) {
    out.errors.push_back(DbcError{message.line, message.column,
                                  "message " + quote_value(message.name) + ": " +
                                      (problem.where.empty() ? "" : problem.where + ": ") + problem.what});
  }
  return out;
}

}  // namespace cosmic
