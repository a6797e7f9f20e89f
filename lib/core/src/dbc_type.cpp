// A typed channel's contents from a DBC message (cosmic/dbc_type.hpp).
#include "cosmic/dbc_type.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <utility>

#include "cosmic/dbc_codec.hpp"

namespace cosmic {
namespace {

constexpr double kExactIntegers = 9007199254740992.0;  // 2^53: doubles are exact integers below it

bool whole(double value) { return std::fabs(value) < kExactIntegers && std::floor(value) == value; }

bool declares_range(const DbcSignal& s) { return s.minimum != 0.0 || s.maximum != 0.0; }

using Wide = __int128;  // exact for every raw value times a whole factor a double holds below 2^53

// The smallest integer kind holding [lowest, highest] exactly; nullopt beyond 64 bits.
std::optional<ScalarKind> smallest_integer(Wide lowest, Wide highest) {
  struct Limits {
    ScalarKind kind;
    Wide low, high;
  };
  static const std::array<Limits, 8> kinds{{
      {ScalarKind::uint8, 0, 0xFF},
      {ScalarKind::uint16, 0, 0xFFFF},
      {ScalarKind::uint32, 0, 0xFFFF'FFFF},
      {ScalarKind::uint64, 0, Wide{std::numeric_limits<std::uint64_t>::max()}},
      {ScalarKind::int8, -128, 127},
      {ScalarKind::int16, -32768, 32767},
      {ScalarKind::int32, Wide{std::numeric_limits<std::int32_t>::min()}, std::numeric_limits<std::int32_t>::max()},
      {ScalarKind::int64, Wide{std::numeric_limits<std::int64_t>::min()}, std::numeric_limits<std::int64_t>::max()},
  }};
  for (const Limits& k : kinds) {
    if ((lowest < 0) == (k.low < 0) && lowest >= k.low && highest <= k.high) return k.kind;
  }
  return std::nullopt;
}

// The raw range of an integer signal, exactly.
std::pair<Wide, Wide> raw_range(const DbcSignal& s) {
  if (!s.is_signed) return {0, (Wide{1} << s.size) - 1};
  return {-(Wide{1} << (s.size - 1)), (Wide{1} << (s.size - 1)) - 1};
}

FieldType scalar(ScalarKind kind) {
  FieldType type;
  type.kind = FieldType::Kind::scalar;
  type.scalar = kind;
  return type;
}

std::string magnitude_text(std::int64_t value) {
  return std::to_string(value < 0 ? 0 - static_cast<std::uint64_t>(value) : static_cast<std::uint64_t>(value));
}

// The kind for the raw range and every named value; nullopt when none holds them all (an unsigned
// 64-bit signal naming a negative value).
std::optional<FieldType> enumeration(const DbcSignal& s) {
  auto [lowest, highest] = raw_range(s);
  for (const DbcValueName& v : s.value_names) {
    lowest = std::min(lowest, Wide{v.value});
    highest = std::max(highest, Wide{v.value});
  }
  const auto kind = smallest_integer(lowest, highest);
  if (!kind) return std::nullopt;
  FieldType type = scalar(*kind);
  type.kind = FieldType::Kind::enumeration;
  std::set<std::string> taken;
  for (const DbcValueName& v : s.value_names) {
    const std::string base = dbc_value_identifier(v.name, v.value);
    std::string name = base;
    // A name given twice gets the value (then a counter) appended, cut to stay within 64 characters.
    for (int again = 0; !taken.insert(name).second; ++again) {
      const std::string suffix = "_" + magnitude_text(v.value) + (again > 0 ? "_" + std::to_string(again) : "");
      name = base.substr(0, 64 - suffix.size()) + suffix;
    }
    type.values.push_back(EnumValue{std::move(name), v.value});
  }
  return type;
}

// A whole factor and offset: the smallest integer holding every physical value and the declared
// range, computed exactly.
std::optional<FieldType> whole_number(const DbcSignal& s) {
  if (!whole(s.factor) || !whole(s.offset)) return std::nullopt;
  const auto [raw_low, raw_high] = raw_range(s);
  const auto factor = static_cast<Wide>(static_cast<std::int64_t>(s.factor));
  const auto offset = static_cast<Wide>(static_cast<std::int64_t>(s.offset));
  Wide lowest = std::min(raw_low * factor + offset, raw_high * factor + offset);
  Wide highest = std::max(raw_low * factor + offset, raw_high * factor + offset);
  if (declares_range(s)) {
    if (std::fabs(s.minimum) >= kExactIntegers || std::fabs(s.maximum) >= kExactIntegers) return std::nullopt;
    lowest = std::min(lowest, static_cast<Wide>(std::floor(s.minimum)));
    highest = std::max(highest, static_cast<Wide>(std::ceil(s.maximum)));
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
  // switch_problem() has checked that this fits.
  return static_cast<std::int64_t>(Wide{raw} * static_cast<std::int64_t>(selector.factor) +
                                   static_cast<std::int64_t>(selector.offset));
}

}  // namespace

FieldType dbc_field_type(const DbcSignal& s) {
  const bool unscaled = s.factor == 1.0 && s.offset == 0.0;
  if (s.value_type == DbcValueType::float32) return scalar(unscaled ? ScalarKind::float32 : ScalarKind::float64);
  if (s.value_type == DbcValueType::float64) return scalar(ScalarKind::float64);
  if (!s.value_names.empty()) return enumeration(s).value_or(scalar(ScalarKind::float64));
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
  if (name.empty()) return "v" + magnitude_text(value);
  if (!((name.front() >= 'A' && name.front() <= 'Z') || (name.front() >= 'a' && name.front() <= 'z')))
    name = "v" + name;
  if (name.size() > 64) name.resize(64);
  while (name.back() == '_') name.pop_back();
  return name;
}

namespace {

// What keeps the switch from selecting its signals as typed fields: it must be an unsigned integer
// field, and every value its signals name must fit its bits and the field.
std::optional<DbcError> switch_problem(const DbcMessage& message, const DbcSignal& selector) {
  const FieldType type = dbc_field_type(selector);
  const bool integral =
      type.kind == FieldType::Kind::enumeration || type.scalar == ScalarKind::boolean || is_integer(type.scalar);
  if (selector.is_signed || !integral) {
    return at(
        selector,
        "multiplexor switch " + quote_value(selector.name) + " is " +
            (selector.is_signed ? "signed" : "not an integer field (an IEEE float, or a scaling that is not whole)") +
            ": the switch's values are the unsigned raw values its multiplexed signals name");
  }
  const Wide raw_high = raw_range(selector).second;
  for (const DbcSignal& s : message.signals) {
    if (s.multiplex != DbcMultiplex::multiplexed) continue;
    const Wide value = Wide{s.multiplex_value} * static_cast<std::int64_t>(selector.factor) +
                       static_cast<std::int64_t>(selector.offset);
    if (Wide{s.multiplex_value} > raw_high || value > std::numeric_limits<std::int64_t>::max()) {
      return at(s, "signal " + quote_value(s.name) + " is selected by " + quote_value(selector.name) + " = " +
                       std::to_string(s.multiplex_value) + ", which the switch's " + std::to_string(selector.size) +
                       " bits cannot hold");
    }
  }
  return std::nullopt;
}

// The switch first (a field's selector comes before it), then the others in the message's order.
std::vector<const DbcSignal*> field_order(const DbcMessage& message, const DbcSignal* selector) {
  std::vector<const DbcSignal*> order;
  if (selector != nullptr) order.push_back(selector);
  for (const DbcSignal& s : message.signals) {
    if (&s != selector) order.push_back(&s);
  }
  return order;
}

std::optional<DbcError> field_problem(const DbcSignal& s) {
  if (!valid_field_name(s.name)) {
    return at(s, "signal name " + quote_value(s.name) +
                     " is not a field name ([A-Za-z][A-Za-z0-9_]*, at most 64 characters)");
  }
  if (s.multiplex == DbcMultiplex::multiplexed_multiplexor) {
    return at(s, "signal " + quote_value(s.name) +
                     " is itself a multiplexor inside a multiplexed frame (extended multiplexing), which typed "
                     "channels do not decode");
  }
  if (!s.value_names.empty() && s.value_type == DbcValueType::integer && !enumeration(s)) {
    return at(s, "signal " + quote_value(s.name) +
                     ": no integer holds both its raw values and the negative values "
                     "its value table names");
  }
  return std::nullopt;
}

}  // namespace

DbcChannelType channel_type_from_dbc(const DbcMessage& message) {
  DbcChannelType out;
  const auto refuse = [&](DbcError error) {
    out.errors.push_back(std::move(error));
    return out;
  };
  if (message.signals.empty()) {
    return refuse(
        {message.line, message.column, "message " + quote_value(message.name) + " has no signals to make fields of"});
  }
  if (message.signals.size() > kMaxRecordFields) {
    return refuse({message.line, message.column,
                   "message " + quote_value(message.name) + " has " + std::to_string(message.signals.size()) +
                       " signals; a type has at most " + std::to_string(kMaxRecordFields) + " fields"});
  }
  if (const auto shared = overlap(message)) return refuse(*shared);
  const DbcSignal* selector = dbc_multiplexor(message);
  if (selector != nullptr) {
    if (const auto problem = switch_problem(message, *selector)) return refuse(*problem);
  }
  for (const DbcSignal* signal : field_order(message, selector)) {
    const DbcSignal& s = *signal;
    if (const auto problem = field_problem(s)) {
      out.errors.push_back(*problem);
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
