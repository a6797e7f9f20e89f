// The DBC codec (cosmic/dbc_codec.hpp). Bit by bit: at most 64 steps a signal, no table, and the
// Motorola walk written once (next_bit), so both byte orders share every loop.
#include "cosmic/dbc_codec.hpp"

#include <bit>
#include <cmath>
#include <limits>

namespace cosmic {
namespace {

constexpr std::uint64_t kNoBit = std::numeric_limits<std::uint64_t>::max();

// The frame bit that holds the signal's most significant bit (Motorola: the start bit) or least
// significant bit (Intel: the start bit), and how to step from one to the next.
struct BitWalk {
  std::uint64_t position;
  bool big_endian;

  // Motorola numbers bits 7..0 within a byte from its most significant bit down; past bit 0 of a
  // byte the signal goes on at bit 7 of the next byte (8 * byte + 15 in DBC's numbering).
  void next() {
    if (!big_endian) {
      ++position;
    } else if (position % 8 == 0) {
      position += 15;
    } else {
      --position;
    }
  }
};

std::uint64_t low_mask(std::uint32_t size) { return size >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << size) - 1; }

bool bit_at(std::span<const std::uint8_t> data, std::uint64_t position) {
  const std::uint64_t byte = position / 8;
  return byte < data.size() && ((data[byte] >> (position % 8)) & 1u) != 0;
}

void set_bit(std::span<std::uint8_t> data, std::uint64_t position, bool value) {
  const std::uint64_t byte = position / 8;
  if (byte >= data.size()) return;
  const auto mask = static_cast<std::uint8_t>(1u << (position % 8));
  data[byte] = value ? static_cast<std::uint8_t>(data[byte] | mask) : static_cast<std::uint8_t>(data[byte] & ~mask);
}

// Signal bit `k` (0 = least significant) for the k-th step of the walk.
std::uint32_t value_bit(const DbcSignal& signal, std::uint32_t step) {
  return signal.order == DbcByteOrder::big_endian ? signal.size - 1 - step : step;
}

}  // namespace

bool dbc_signal_fits(const DbcSignal& signal, std::size_t frame_bytes) {
  if (signal.size == 0 || signal.size > 64) return false;
  const std::uint64_t bits = std::uint64_t{frame_bytes} * 8;
  BitWalk walk{signal.start_bit, signal.order == DbcByteOrder::big_endian};
  for (std::uint32_t step = 0; step < signal.size; ++step, walk.next()) {
    if (walk.position >= bits) return false;
  }
  return true;
}

std::uint64_t dbc_read_bits(const DbcSignal& signal, std::span<const std::uint8_t> data) {
  std::uint64_t bits = 0;
  BitWalk walk{signal.start_bit, signal.order == DbcByteOrder::big_endian};
  for (std::uint32_t step = 0; step < signal.size && step < 64; ++step, walk.next()) {
    if (bit_at(data, walk.position)) bits |= std::uint64_t{1} << value_bit(signal, step);
  }
  return bits;
}

void dbc_write_bits(const DbcSignal& signal, std::uint64_t bits, std::span<std::uint8_t> data) {
  BitWalk walk{signal.start_bit, signal.order == DbcByteOrder::big_endian};
  for (std::uint32_t step = 0; step < signal.size && step < 64; ++step, walk.next()) {
    set_bit(data, walk.position, ((bits >> value_bit(signal, step)) & 1u) != 0);
  }
}

std::int64_t dbc_raw_integer(const DbcSignal& signal, std::uint64_t bits) {
  bits &= low_mask(signal.size);
  if (!signal.is_signed || signal.size >= 64 || signal.size == 0) return static_cast<std::int64_t>(bits);
  const std::uint64_t sign = std::uint64_t{1} << (signal.size - 1);
  return static_cast<std::int64_t>((bits ^ sign) - sign);  // two's complement sign extension
}

std::int64_t dbc_raw_minimum(const DbcSignal& signal) {
  if (!signal.is_signed || signal.size == 0) return 0;
  if (signal.size >= 64) return std::numeric_limits<std::int64_t>::min();
  return -(std::int64_t{1} << (signal.size - 1));
}

std::int64_t dbc_raw_maximum(const DbcSignal& signal) {
  if (signal.size == 0) return 0;
  if (signal.is_signed)
    return signal.size >= 64 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << (signal.size - 1)) - 1;
  return signal.size >= 63 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << signal.size) - 1;
}

double dbc_physical(const DbcSignal& signal, std::uint64_t bits) {
  double raw = 0.0;
  switch (signal.value_type) {
    case DbcValueType::float32:
      raw = std::bit_cast<float>(static_cast<std::uint32_t>(bits));
      break;
    case DbcValueType::float64:
      raw = std::bit_cast<double>(bits);
      break;
    case DbcValueType::integer:
      raw = signal.is_signed ? static_cast<double>(dbc_raw_integer(signal, bits))
                             : static_cast<double>(bits & low_mask(signal.size));
      break;
  }
  return raw * signal.factor + signal.offset;
}

std::optional<std::uint64_t> dbc_bits_for(const DbcSignal& signal, double physical) {
  const double raw = signal.factor == 0.0 ? 0.0 : (physical - signal.offset) / signal.factor;
  if (signal.value_type == DbcValueType::float32) {
    if (std::isfinite(raw) && std::fabs(raw) > std::numeric_limits<float>::max()) return std::nullopt;
    return std::bit_cast<std::uint32_t>(static_cast<float>(raw));
  }
  if (signal.value_type == DbcValueType::float64) return std::bit_cast<std::uint64_t>(raw);
  if (!std::isfinite(raw)) return std::nullopt;
  const double rounded = std::nearbyint(raw);
  if (!signal.is_signed) {
    // 2^size as a double is exact; the largest raw value is one below it.
    if (rounded < 0.0 || rounded >= std::ldexp(1.0, static_cast<int>(signal.size))) return std::nullopt;
    return static_cast<std::uint64_t>(rounded);
  }
  const double half = std::ldexp(1.0, static_cast<int>(signal.size) - 1);
  if (rounded < -half || rounded >= half) return std::nullopt;
  return static_cast<std::uint64_t>(static_cast<std::int64_t>(rounded)) & low_mask(signal.size);
}

std::uint64_t dbc_saturated_bits_for(const DbcSignal& signal, double physical) {
  if (const auto bits = dbc_bits_for(signal, physical)) return *bits;
  if (std::isnan(physical)) return 0;
  const double raw = signal.factor == 0.0 ? 0.0 : (physical - signal.offset) / signal.factor;
  if (signal.value_type == DbcValueType::float32) {
    return std::bit_cast<std::uint32_t>(raw < 0 ? std::numeric_limits<float>::lowest()
                                                : std::numeric_limits<float>::max());
  }
  const bool low = std::isnan(raw) || raw < 0.0;
  if (!signal.is_signed) return low ? 0 : low_mask(signal.size);
  const auto extreme = low ? dbc_raw_minimum(signal) : dbc_raw_maximum(signal);
  return static_cast<std::uint64_t>(extreme) & low_mask(signal.size);
}

const DbcSignal* dbc_multiplexor(const DbcMessage& message) {
  for (const DbcSignal& s : message.signals) {
    if (s.multiplex == DbcMultiplex::multiplexor) return &s;
  }
  return nullptr;
}

bool dbc_signal_present(const DbcMessage& message, const DbcSignal& signal, std::span<const std::uint8_t> data) {
  if (signal.multiplex != DbcMultiplex::multiplexed && signal.multiplex != DbcMultiplex::multiplexed_multiplexor) {
    return true;
  }
  const DbcSignal* selector = dbc_multiplexor(message);
  if (selector == nullptr) return false;
  const std::uint64_t value = dbc_read_bits(*selector, data);
  return value == signal.multiplex_value;
}

}  // namespace cosmic
