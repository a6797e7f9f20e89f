// A typed channel's DBC frames (cosmic/dbc_frames.hpp). Integer fields convert in whole numbers
// (128-bit intermediates: a 64-bit raw value times a whole factor), so no value is rounded through
// a double; float fields go through the signal's own scaling (cosmic/dbc_codec.hpp).
#include "cosmic/dbc_frames.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "cosmic/dbc_codec.hpp"
#include "cosmic/dbc_type.hpp"

namespace cosmic {
namespace {

using Wide = __int128;

Wide raw_low(const DbcSignal& s) { return s.is_signed ? -(Wide{1} << (s.size - 1)) : Wide{0}; }
Wide raw_high(const DbcSignal& s) { return s.is_signed ? (Wide{1} << (s.size - 1)) - 1 : (Wide{1} << s.size) - 1; }

std::uint64_t bits_of(const DbcSignal& s, Wide raw) {
  const std::uint64_t mask = s.size >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << s.size) - 1;
  return static_cast<std::uint64_t>(raw) & mask;
}

// The bits of a raw integer, or nullopt when the signal does not hold it.
std::optional<std::uint64_t> bits_for_raw(const DbcSignal& s, Wide raw) {
  if (raw < raw_low(s) || raw > raw_high(s)) return std::nullopt;
  return bits_of(s, raw);
}

std::uint64_t saturated_raw_bits(const DbcSignal& s, Wide raw) {
  return bits_of(s, std::clamp(raw, raw_low(s), raw_high(s)));
}

// (value - offset) / factor to the nearest whole number, halves away from zero.
Wide whole_raw(Wide value, std::int64_t factor, std::int64_t offset) {
  const Wide q = value - offset;
  Wide raw = q / factor;
  const Wide rest = q % factor;
  const Wide magnitude = rest < 0 ? -rest : rest;
  const Wide divisor = factor < 0 ? -Wide{factor} : Wide{factor};
  if (2 * magnitude >= divisor) raw += ((q < 0) != (factor < 0)) ? -1 : 1;
  return raw;
}

Wide slot_integer(ScalarKind kind, const ScalarValue& v) {
  return is_signed_integer(kind) ? Wide{v.integer} : Wide{v.unsigned_integer};
}

ScalarValue integer_value(ScalarKind kind, Wide value) {
  ScalarValue v;
  if (is_signed_integer(kind)) {
    v.integer = static_cast<std::int64_t>(value);
  } else {
    v.unsigned_integer = static_cast<std::uint64_t>(value);
  }
  return v;
}

}  // namespace

Result<DbcFrameCodec> DbcFrameCodec::make(const DbcMessage& message, const ChannelType& type) {
  const DbcChannelType own = channel_type_from_dbc(message);
  if (!own.ok()) return Error{own.errors.front().message};
  if (own.type.fields != type.fields) {
    return Error{"the channel's type is not the type of DBC message " + message.name + " (" + describe(own.type) + ")"};
  }
  auto layout = CompactLayout::of_flat_record(type);
  if (!layout) return std::move(layout).error();
  DbcFrameCodec codec;
  codec.message_ = message;
  if (const DbcSignal* selector = dbc_multiplexor(message)) {
    codec.switch_ = static_cast<std::size_t>(selector - message.signals.data());
  }
  codec.layout_ = std::move(layout).value();
  for (std::size_t i = 0; i < type.fields.size(); ++i) {
    // The fields come in the type's order (the multiplexor switch first), the signals in the file's.
    const auto signal = std::find_if(message.signals.begin(), message.signals.end(),
                                     [&](const DbcSignal& s) { return s.name == type.fields[i].name; });
    // The same names: the type is the message's own, so every field fits its signal.
    Result<FieldCodec> f =
        field_codec(*signal, static_cast<std::size_t>(signal - message.signals.begin()), type.fields[i], i, false);
    if (!f) return std::move(f).error();
    codec.fields_.push_back(f.value());
  }
  return codec;
}

namespace {

bool is_whole(double v) { return std::isfinite(v) && std::trunc(v) == v && std::fabs(v) < 9.0e15; }

std::string number(double v) { return shortest_number_text(v); }

// Why `signal` cannot hold the declared range or the values of `field`, or empty.
std::string too_narrow(const DbcSignal& signal, const TypeField& field, bool raw) {
  if (signal.value_type != DbcValueType::integer) return {};
  const double low = static_cast<double>(raw_low(signal)), high = static_cast<double>(raw_high(signal));
  if (raw) {
    for (const EnumValue& v : field.type.values) {
      if (static_cast<double>(v.value) < low || static_cast<double>(v.value) > high) {
        return "signal " + signal.name + " holds raw values " + number(low) + ".." + number(high) + ", not field " +
               field.name + "'s value " + v.name + " = " + std::to_string(v.value);
      }
    }
    return {};
  }
  const double a = low * signal.factor + signal.offset, b = high * signal.factor + signal.offset;
  const double lowest = std::min(a, b), highest = std::max(a, b);
  const bool narrow = (field.minimum && *field.minimum < lowest) || (field.maximum && *field.maximum > highest);
  if (!narrow) return {};
  return "signal " + signal.name + " holds " + number(lowest) + ".." + number(highest) + ", narrower than field " +
         field.name + "'s range " + (field.minimum ? number(*field.minimum) : "") + ".." +
         (field.maximum ? number(*field.maximum) : "");
}

}  // namespace

Result<DbcFrameCodec::FieldCodec> DbcFrameCodec::field_codec(const DbcSignal& s, std::size_t signal_index,
                                                             const TypeField& field, std::size_t slot, bool mapped) {
  const FieldType& type = field.type;
  if (type.kind != FieldType::Kind::scalar && type.kind != FieldType::Kind::enumeration) {
    return Error{"field " + field.name + " is not a number: a DBC signal carries one number"};
  }
  FieldCodec f;
  f.signal = signal_index;
  f.slot = slot;
  f.raw = type.kind == FieldType::Kind::enumeration || type.scalar == ScalarKind::boolean;
  f.whole = !f.raw && is_integer(type.scalar);
  // The message's own type fits by construction (dbc_field_type); its declared range may be wider
  // than the raw bits, as DBC files often declare.
  if (!mapped) {
    if (f.whole) {
      f.factor = static_cast<std::int64_t>(s.factor);
      f.offset = static_cast<std::int64_t>(s.offset);
    }
    return f;
  }
  if ((f.raw || f.whole) && s.value_type != DbcValueType::integer) {
    return Error{"field " + field.name + " is an integer, and signal " + s.name + " an IEEE float"};
  }
  if (f.whole) {
    if (!is_whole(s.factor) || !is_whole(s.offset) || s.factor == 0) {
      return Error{"field " + field.name + " is an integer, and signal " + s.name + "'s scaling (" + number(s.factor) +
                   ", " + number(s.offset) + ") is not whole"};
    }
    f.factor = static_cast<std::int64_t>(s.factor);
    f.offset = static_cast<std::int64_t>(s.offset);
  }
  // An enumeration's value the signal cannot hold would arrive as another value: never carried.
  if (f.raw) {
    if (const std::string why = too_narrow(s, field, true); !why.empty()) return Error{why};
  }
  return f;
}

namespace {

// `type` with its nested records' fields lifted to the top as PATH.FIELD ("linear.x"), in order:
// the same compact layout (a record is its fields), one name per scalar.
void lift_leaves(const std::vector<TypeField>& fields, const std::string& prefix, std::vector<TypeField>& out) {
  for (const TypeField& field : fields) {
    if (field.type.kind == FieldType::Kind::record) {
      lift_leaves(field.type.fields, prefix + field.name + ".", out);
      continue;
    }
    TypeField leaf = field;
    leaf.name = prefix + field.name;
    if (leaf.present_when && !prefix.empty()) leaf.present_when->selector = prefix + leaf.present_when->selector;
    out.push_back(std::move(leaf));
  }
}

bool has_leaf(const ChannelType& leaves, const std::string& name) {
  return std::any_of(leaves.fields.begin(), leaves.fields.end(), [&](const TypeField& f) { return f.name == name; });
}

}  // namespace

Result<DbcFrameCodec> DbcFrameCodec::make_mapped(const DbcMessage& message, const ChannelType& type,
                                                 const std::map<std::string, std::string>& field_map,
                                                 const std::vector<std::string>& omitted) {
  if (dbc_multiplexor(message) != nullptr) {
    return Error{"message " + message.name +
                 " is multiplexed: the signal gateway re-packs messages without"
                 " multiplexing"};
  }
  ChannelType leaves;
  lift_leaves(type.fields, "", leaves.fields);
  for (const auto& entry : field_map) {
    if (!has_leaf(leaves, entry.first))
      return Error{"map names field " + entry.first + ", which the channel's type does not have"};
  }
  for (const std::string& name : omitted) {
    if (!has_leaf(leaves, name)) return Error{"omit names field " + name + ", which the channel's type does not have"};
    if (field_map.count(name) != 0) return Error{"field " + name + " is both mapped and omitted"};
  }
  auto layout = CompactLayout::of_flat_record(leaves);
  if (!layout) return std::move(layout).error();
  DbcFrameCodec codec;
  codec.message_ = message;
  codec.layout_ = std::move(layout).value();
  std::map<std::size_t, std::string> taken;  // signal index -> the field it carries
  for (std::size_t i = 0; i < leaves.fields.size(); ++i) {
    const TypeField& field = leaves.fields[i];
    if (std::find(omitted.begin(), omitted.end(), field.name) != omitted.end()) continue;
    const auto mapped = field_map.find(field.name);
    const std::string& name = mapped != field_map.end() ? mapped->second : field.name;
    const auto signal = std::find_if(message.signals.begin(), message.signals.end(),
                                     [&](const DbcSignal& s) { return s.name == name; });
    if (signal == message.signals.end()) {
      return Error{"field " + field.name + " has no signal " + name + " in message " + message.name +
                   (mapped != field_map.end()
                        ? ""
                        : " (map: {" + field.name + ": SIGNAL} names the one that carries it, omit: [" + field.name +
                              "] leaves it out)")};
    }
    const auto index = static_cast<std::size_t>(signal - message.signals.begin());
    if (const auto [other, fresh] = taken.emplace(index, field.name); !fresh) {
      return Error{"fields " + other->second + " and " + field.name + " are both mapped to signal " + name};
    }
    Result<FieldCodec> f = field_codec(*signal, index, field, i, true);
    if (!f) return Error{"message " + message.name + ": " + f.error().text};
    if (!f.value().raw) {
      if (std::string why = too_narrow(*signal, field, false); !why.empty()) codec.narrowed_.push_back(std::move(why));
    }
    codec.fields_.push_back(f.value());
  }
  return codec;
}

bool DbcFrameCodec::to_compact(std::span<const std::uint8_t> frame, std::span<std::uint8_t> compact) const {
  if (frame.size() < message_.length || compact.size() < layout_.size()) return false;
  const auto data = frame.first(message_.length);
  std::fill_n(compact.begin(), layout_.size(), std::uint8_t{0});
  // The switch is read once per frame, not once per multiplexed signal (dbc_signal_present).
  const std::uint64_t selected = switch_ ? dbc_read_bits(message_.signals[*switch_], data) : 0;
  for (const FieldCodec& f : fields_) {
    const DbcSignal& s = message_.signals[f.signal];
    if (s.multiplex == DbcMultiplex::multiplexed && (!switch_ || selected != s.multiplex_value)) continue;
    const CompactLayout::Slot& slot = layout_.slots()[f.slot];
    const std::uint64_t bits = dbc_read_bits(s, data);
    const Wide raw = s.is_signed ? Wide{dbc_raw_integer(s, bits)} : Wide{bits};
    ScalarValue value;
    if (f.raw) {
      value = integer_value(slot.kind, raw);
    } else if (f.whole) {
      value = integer_value(slot.kind, raw * f.factor + f.offset);
    } else {
      value.real = dbc_physical(s, bits);
    }
    write_scalar(slot.kind, value, compact.data() + slot.offset);
  }
  return true;
}

DbcFrameCodec::Packed DbcFrameCodec::to_frame(std::span<const std::uint8_t> compact, std::span<std::uint8_t> frame,
                                              RangePolicy policy) const {
  Packed packed;
  if (compact.size() < layout_.size() || frame.size() < message_.length) return packed;
  const auto data = frame.first(message_.length);
  std::fill(data.begin(), data.end(), std::uint8_t{0});
  for (const FieldCodec& f : fields_) {
    if (!layout_.present(f.slot, compact)) continue;
    const DbcSignal& s = message_.signals[f.signal];
    const CompactLayout::Slot& slot = layout_.slots()[f.slot];
    const ScalarValue value = read_scalar(slot.kind, compact.data() + slot.offset);
    std::optional<std::uint64_t> bits;
    std::uint64_t saturated = 0;
    if (f.raw || f.whole) {
      const Wide integer = slot_integer(slot.kind, value);
      const Wide raw = f.whole ? whole_raw(integer, f.factor, f.offset) : integer;
      bits = bits_for_raw(s, raw);
      if (!bits) saturated = saturated_raw_bits(s, raw);
    } else {
      bits = dbc_bits_for(s, value.real);
      if (!bits) saturated = dbc_saturated_bits_for(s, value.real);
    }
    if (!bits) {
      ++packed.out_of_range;
      if (policy == RangePolicy::drop) return packed;
      bits = saturated;
    }
    dbc_write_bits(s, *bits, data);
  }
  packed.sent = true;
  return packed;
}

}  // namespace cosmic
