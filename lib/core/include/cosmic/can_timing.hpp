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

// Largest identifier of each format.
// ceil(numerator / denominator) for denominator > 0; 0 for numerator <= 0 (releases of a
// periodic frame within an interval, windows of the fault hypothesis).
constexpr std::int64_t ceil_div(std::int64_t numerator, std::int64_t denominator) {
  return numerator <= 0 ? 0 : (numerator + denominator - 1) / denominator;
}

inline constexpr std::uint32_t kStandardIdMax = 0x7FF;
inline constexpr std::uint32_t kExtendedIdMax = 0x1FFFFFFF;

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
// Whether a frame can carry exactly `length` data bytes (0..8; on CAN FD also the FD lengths).
bool is_frame_length(std::uint32_t length, bool fd);
// Data bytes of DLC code 0..15 (9..15: the CAN FD lengths 12..64).
std::uint32_t dlc_length(std::uint32_t dlc);

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

// Where a frame stands in arbitration, comparable across identifier formats: lower wins.
// The 11 base bits go on the wire first; on equal base bits a standard frame (RTR/IDE dominant)
// beats an extended one (SRR/IDE recessive); two extended frames then compare their 18 low bits.
// Key = base(11) << 19 | extended << 18 | low(18), so standard id S gets S << 19 and extended id
// E gets (E >> 18) << 19 | 1 << 18 | (E & 0x3FFFF): ordering keys orders the frames as the bus does.
constexpr std::uint32_t arbitration_key(std::uint32_t id, CanIdFormat format) {
  if (format == CanIdFormat::standard11) return (id & 0x7FFu) << 19;
  return ((id >> 18) & 0x7FFu) << 19 | 1u << 18 | (id & 0x3FFFFu);
}

// One periodic/sporadic message stream on a bus.
struct CanStream {
  std::uint32_t can_id = 0;  // arbitration_key() of the stream's identifier: lower value wins
  Nanos transmission{0};     // C
  Nanos period{0};           // T, minimum inter-arrival time (> 0)
  Nanos jitter{0};           // J, queuing jitter
};

struct CanBusTiming {
  Nanos bit_time{0};          // tau_bit
  Nanos error_frame_time{0};  // kErrorFrameBits nominal bits
  CanFaultHypothesis errors;
  friend bool operator==(const CanBusTiming&, const CanBusTiming&) = default;
};

CanBusTiming bus_timing(const CanSegmentProperties& bus);

// Worst-case response time R = J + w + C of every stream (same order as the input), or nullopt
// when the busy period does not end (the streams of higher or equal priority overload the bus).
std::vector<std::optional<Nanos>> response_times(std::span<const CanStream> streams, const CanBusTiming& timing);

// response_times() kept for the next analysis of the same bus, so that the next one re-examines
// only what changed. A stream's result depends on its own C, T, J, on the ordered list of
// higher-priority streams, on its blocking and on the bus timing; when all of these equal what
// `previous` saw at the same place in priority order, the result is reused without iteration.
// A newcomer therefore re-examines the streams of equal or lower priority, plus higher ones whose
// blocking its frame lengthens. Overload of a priority level (utilization >= 100 %, faults
// included) is found from prefix sums before any fixed-point iteration, and each iteration
// visits only the higher-priority streams released more than once in the interval (the others
// are a prefix sum), so a long bus of rarely-interfering streams costs about O(n log n).
//
// Plain value, cheap to copy (a few vectors of numbers, O(streams)). Pure: no I/O, no state
// shared between instances.
class CanBusAnalysis {
 public:
  CanBusAnalysis() = default;
  CanBusAnalysis(std::span<const CanStream> streams, const CanBusTiming& timing,
                 const CanBusAnalysis* previous = nullptr);

  // Same order as the input streams.
  const std::vector<std::optional<Nanos>>& results() const { return results_; }
  // How many streams went through the fixed-point iteration (the others were reused).
  std::size_t analysed() const { return analysed_; }

 private:
  // One stream at its place in priority order (lowest can_id first) and what decided its result.
  struct Entry {
    std::int64_t transmission = 0;
    std::int64_t period = 0;
    std::int64_t jitter = 0;
    bool tied = false;       // same can_id as the entry before it (same channel on both sides)
    bool near_full = false;  // level load within rounding of 100 %: never reused
    std::int64_t blocking = 0;
    std::optional<Nanos> result;
    bool same_stream(const Entry& other) const;
  };

  CanBusTiming timing_;
  std::vector<Entry> entries_;
  std::vector<std::optional<Nanos>> results_;
  std::size_t analysed_ = 0;
};

// Sum of C/T over the streams.
double utilization(std::span<const CanStream> streams);

}  // namespace cosmic
