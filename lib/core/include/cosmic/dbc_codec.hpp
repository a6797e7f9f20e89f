// Packing and unpacking the signals of a DBC message (cosmic/dbc.hpp) in a CAN frame's data:
// Intel and Motorola bit numbering, signed and unsigned integers of 1 to 64 bits, IEEE floats,
// scaling (physical = raw * factor + offset) and simple multiplexing. Pure functions on caller
// buffers: no allocation, no I/O, never throw; any thread. Every function expects a signal that
// dbc_signal_fits() the data it is given (parse_dbc() only returns such signals for the message's
// own length); a smaller buffer reads as zero bits and is not written past its end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "cosmic/dbc.hpp"

namespace cosmic {

// Whether every bit of the signal lies within `frame_bytes` bytes of data.
bool dbc_signal_fits(const DbcSignal& signal, std::size_t frame_bytes);

// The signal's raw bits, right-aligned (bit 0 is the signal's least significant bit).
std::uint64_t dbc_read_bits(const DbcSignal& signal, std::span<const std::uint8_t> data);
// Writes the low `signal.size` bits of `bits` into the signal's place, leaving other bits as they are.
void dbc_write_bits(const DbcSignal& signal, std::uint64_t bits, std::span<std::uint8_t> data);

// The raw value of an integer signal, sign-extended when it is signed (as VAL_ names values).
std::int64_t dbc_raw_integer(const DbcSignal& signal, std::uint64_t bits);
// The lowest and highest raw integers the signal's bits hold (unsigned 64-bit signals: as int64
// their highest is clamped to INT64_MAX; use dbc_read_bits for the full range).
std::int64_t dbc_raw_minimum(const DbcSignal& signal);
std::int64_t dbc_raw_maximum(const DbcSignal& signal);

// The physical value the signal's bits carry: raw * factor + offset, the raw an integer or an
// IEEE float as the signal's value type says.
double dbc_physical(const DbcSignal& signal, std::uint64_t bits);

// The bits that carry `physical`: (physical - offset) / factor rounded to the nearest raw integer,
// or converted to the IEEE float. nullopt when the raw value does not fit the signal's bits (or is
// not a finite number, for an integer signal): the caller counts it, drops it or saturates.
std::optional<std::uint64_t> dbc_bits_for(const DbcSignal& signal, double physical);
// The bits of the nearest raw value the signal holds (saturation; NaN becomes 0).
std::uint64_t dbc_saturated_bits_for(const DbcSignal& signal, double physical);

// Whether a frame with `data` carries the signal: always, unless it is multiplexed and the
// message's switch (the signal with DbcMultiplex::multiplexor) holds another value. A multiplexed
// signal of a message without a switch is never present (parse_dbc() refuses such a message).
bool dbc_signal_present(const DbcMessage& message, const DbcSignal& signal, std::span<const std::uint8_t> data);

// The message's multiplexor switch, if it has one.
const DbcSignal* dbc_multiplexor(const DbcMessage& message);

}  // namespace cosmic
