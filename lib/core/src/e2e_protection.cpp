#include "cosmic/e2e_protection.hpp"

#include <algorithm>
#include <array>

#include "cosmic/dbc_codec.hpp"

namespace cosmic {
namespace {

// One table for the polynomial 0x1D, built at compile time.
constexpr std::array<std::uint8_t, 256> kJ1850Table = [] {
  std::array<std::uint8_t, 256> table{};
  for (unsigned byte = 0; byte < 256; ++byte) {
    auto reg = static_cast<std::uint8_t>(byte);
    for (int bit = 0; bit < 8; ++bit) reg = static_cast<std::uint8_t>((reg & 0x80) ? (reg << 1) ^ 0x1D : reg << 1);
    table[byte] = reg;
  }
  return table;
}();

Error e2e_error(const std::string& why) { return Error{why, 0, kNoChannel}; }

const DbcSignal* find_signal(const DbcMessage& message, const std::string& name) {
  const auto it =
      std::find_if(message.signals.begin(), message.signals.end(), [&](const DbcSignal& s) { return s.name == name; });
  return it == message.signals.end() ? nullptr : &*it;
}

// Why `signal` cannot be the `role` signal of message, or empty.
std::string unfit(const DbcMessage& message, const DbcSignal* signal, const std::string& name, const char* role) {
  if (signal == nullptr) return "no signal " + name + " in message " + message.name + " for the " + role;
  if (signal->multiplex != DbcMultiplex::none)
    return "the " + std::string(role) + " signal " + name + " takes part in multiplexing; it must be in every frame";
  if (signal->value_type != DbcValueType::integer || signal->is_signed)
    return "the " + std::string(role) + " signal " + name + " is not an unsigned integer";
  return {};
}

// The byte an 8-bit signal fills exactly, if it does.
std::optional<std::size_t> whole_byte(const DbcSignal& signal) {
  if (signal.size != 8) return std::nullopt;
  const std::uint32_t lowest = signal.order == DbcByteOrder::little_endian ? 0 : 7;
  if (signal.start_bit % 8 != lowest) return std::nullopt;
  return signal.start_bit / 8;
}

}  // namespace

const char* to_string(E2eDataIdMode mode) {
  switch (mode) {
    case E2eDataIdMode::both:
      return "both";
    case E2eDataIdMode::low:
      return "low";
    case E2eDataIdMode::alt:
      return "alt";
  }
  return "both";
}

std::uint8_t crc8_j1850(std::span<const std::uint8_t> bytes, std::uint8_t start) noexcept {
  std::uint8_t reg = start;
  for (const std::uint8_t b : bytes) reg = kJ1850Table[static_cast<std::uint8_t>(reg ^ b)];
  return reg;
}

E2eProtection::E2eProtection(DbcSignal counter, std::size_t crc_byte, std::size_t length, E2eSpec spec)
    : counter_(std::move(counter)),
      crc_byte_(crc_byte),
      length_(length),
      modulus_(counter_.size == 4 ? 15u : 1u << counter_.size),
      spec_(std::move(spec)) {}

Result<E2eProtection> E2eProtection::make(const DbcMessage& message, const E2eSpec& spec) {
  if (spec.counter == spec.crc) return e2e_error("the counter and the CRC are one signal, " + spec.crc);
  const DbcSignal* counter = find_signal(message, spec.counter);
  const DbcSignal* crc = find_signal(message, spec.crc);
  for (const std::string& why :
       {unfit(message, counter, spec.counter, "counter"), unfit(message, crc, spec.crc, "CRC")}) {
    if (!why.empty()) return e2e_error(why);
  }
  if (counter->size < 2 || counter->size > 16) {
    return e2e_error("the counter signal " + spec.counter + " has " + std::to_string(counter->size) +
                     " bits; a counter has 2 to 16 (4 for AUTOSAR profile 1)");
  }
  const std::optional<std::size_t> crc_byte = whole_byte(*crc);
  if (!crc_byte) {
    return e2e_error("the CRC signal " + spec.crc + " does not fill one whole byte of the frame (" +
                     std::to_string(crc->size) + " bits at start bit " + std::to_string(crc->start_bit) +
                     "); CRC-8 needs one byte of its own");
  }
  if (message.length < 2) return e2e_error("message " + message.name + " has no byte to protect beside its CRC");
  std::array<std::uint8_t, 64> probe{};
  dbc_write_bits(*counter, ~std::uint64_t{0}, std::span(probe).first(message.length));
  if (probe[*crc_byte] != 0)
    return e2e_error("the counter signal " + spec.counter + " overlaps the CRC signal " + spec.crc);
  return E2eProtection(*counter, *crc_byte, message.length, spec);
}

std::uint8_t E2eProtection::crc_of(std::span<const std::uint8_t> frame, std::uint32_t counter) const noexcept {
  if (frame.size() < length_) return 0;
  const std::uint8_t low = static_cast<std::uint8_t>(spec_.data_id & 0xFF);
  const std::uint8_t high = static_cast<std::uint8_t>(spec_.data_id >> 8);
  std::uint8_t reg = 0x00;
  switch (spec_.data_id_mode) {
    case E2eDataIdMode::both:
      reg = crc8_j1850(std::span<const std::uint8_t>(&low, 1), reg);
      reg = crc8_j1850(std::span<const std::uint8_t>(&high, 1), reg);
      break;
    case E2eDataIdMode::low:
      reg = crc8_j1850(std::span<const std::uint8_t>(&low, 1), reg);
      break;
    case E2eDataIdMode::alt:
      reg = crc8_j1850(std::span<const std::uint8_t>(counter % 2 == 0 ? &low : &high, 1), reg);
      break;
  }
  reg = crc8_j1850(frame.first(crc_byte_), reg);
  return crc8_j1850(frame.subspan(crc_byte_ + 1, length_ - crc_byte_ - 1), reg);
}

E2eReading E2eProtection::check(std::span<const std::uint8_t> frame) const noexcept {
  if (frame.size() < length_) return {};
  const auto counter = static_cast<std::uint32_t>(dbc_read_bits(counter_, frame));
  if (counter >= modulus_) return {false, counter};
  return {frame[crc_byte_] == crc_of(frame, counter), counter};
}

void E2eProtection::protect(std::span<std::uint8_t> frame, std::uint64_t counter) const noexcept {
  if (frame.size() < length_) return;
  const auto value = static_cast<std::uint32_t>(counter % modulus_);
  dbc_write_bits(counter_, value, frame);
  frame[crc_byte_] = crc_of(frame, value);
}

DbcMessage e2e_payload_message(const DbcMessage& message, const E2eSpec& spec) {
  DbcMessage payload = message;
  std::erase_if(payload.signals, [&](const DbcSignal& s) { return s.name == spec.counter || s.name == spec.crc; });
  return payload;
}

E2eStep e2e_step(std::optional<std::uint32_t> previous, std::uint32_t counter, std::uint32_t modulus) noexcept {
  if (!previous || modulus == 0) return {};
  const std::uint32_t delta = (counter + modulus - *previous % modulus) % modulus;
  if (delta == 0) return {true, 0};
  return {false, delta - 1};
}

}  // namespace cosmic
