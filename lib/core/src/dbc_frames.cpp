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
    const DbcSignal& s = *signal;  // the same names: the type is the message's own
    const FieldType& field = type.fields[i].type;
    FieldCodec f;
    f.signal = static_cast<std::size_t>(signal - message.signals.begin());
    f.slot = i;
    f.raw = field.kind == FieldType::Kind::enumeration || field.scalar == ScalarKind::boolean;
    f.whole = !f.raw && is_integer(field.scalar);
    if (f.whole) {
      f.factor = static_cast<std::int64_t>(s.factor);  // whole by dbc_field_type's rule
      f.offset = static_cast<std::int64_t>(s.offset);
    }
    codec.fields_.push_back(f);
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
