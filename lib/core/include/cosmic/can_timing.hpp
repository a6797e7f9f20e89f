// CAN frame transmission times and worst-case response-time analysis.
//
// Frame times use worst-case bit stuffing. Response times follow the revised analysis of
// Davis, Burns, Bril and Lukkien, "Controller Area Network (CAN) schedulability analysis:
// Refuted, revisited and revised" (Real-Time Systems 35, 2007), sufficient test with the busy
// period and every instance q inside it, extended by an error-recovery term for a fault
// hypothesis of at most N error frames in any window W. Pure functions.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "cosmic/model.hpp"

namespace cosmic {

enum class CanIdFormat { standard11, extended29 };

// Largest payload of one frame.
inline constexpr std::uint32_t kClassicMaxPayload = 8;
inline constexpr std::uint32_t kFdMaxPayload = 64;
// Worst-case length of an error frame including the following interframe space, in bit times.
inline constexpr std::uint32_t kErrorFrameBits = 31;

// Classic CAN worst-case frame length in bits: g + 8s + 13 + floor((g + 8s - 1) / 4),
// g = 34 (11-bit id) or 54 (29-bit id). 8 bytes extended: 160 bits.
std::uint32_t classic_frame_bits(std::uint32_t payload, CanIdFormat format);

// CAN FD frames carry 0..8, 12, 16, 20, 24, 32, 48 or 64 bytes; a payload is padded up.
std::uint32_t fd_padded_length(std::uint32_t payload);

// Bits of a CAN FD frame sent at the nominal (arbitration) rate and at the data rate,
// worst-case stuffing: dynamic stuff bits in arbitration and data, fixed stuff bits in the CRC.
struct FdFrameBits {
  std::uint32_t nominal_bits = 0;
  std::uint32_t data_bits = 0;
};
FdFrameBits fd_frame_bits(std::uint32_t payload, CanIdFormat format);

// Time of one nominal bit (rounded up to a whole nanosecond: conservative).
Nanos bit_time(BitRate rate);
// Worst-case time to transmit one frame on this bus (classic or FD as configured).
Nanos frame_time(const CanSegmentProperties& bus, std::uint32_t payload, CanIdFormat format);
// Largest payload of one frame on this bus.
std::uint32_t max_frame_payload(const CanSegmentProperties& bus);

// One periodic/sporadic message stream on a bus.
struct CanStream {
  std::uint32_t can_id = 0;  // lower value wins arbitration
  Nanos transmission{0};     // C
  Nanos period{0};           // T, minimum inter-arrival time (> 0)
  Nanos jitter{0};           // J, queuing jitter
};

struct CanBusTiming {
  Nanos bit_time{0};           // tau_bit
  Nanos error_frame_time{0};   // kErrorFrameBits nominal bits
  CanFaultHypothesis errors;
};

CanBusTiming bus_timing(const CanSegmentProperties& bus);

// Worst-case response time R = J + w + C of every stream (same order as the input), or nullopt
// when the busy period does not end (the streams of higher or equal priority overload the bus).
std::vector<std::optional<Nanos>> response_times(std::span<const CanStream> streams, const CanBusTiming& timing);

// Sum of C/T over the streams.
double utilization(std::span<const CanStream> streams);

}  // namespace cosmic
