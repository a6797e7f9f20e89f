// Other devices' frames on a CAN bus (CanSegmentProperties::background) as the response-time
// analysis sees them: streams that interfere with the gateway's frames whose identifiers they
// beat in arbitration and block those they lose to, and load on the bus. Pure functions.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cosmic/can_timing.hpp"
#include "cosmic/model.hpp"

namespace cosmic {

CanIdFormat id_format(const CanBackgroundFrame& frame);
// "0x123" (standard) or "0x18EFFF01" (extended): how reports and errors name an identifier.
std::string can_id_text(std::uint32_t id, bool extended);

// The bus's background frames as analysis streams (can_id = arbitration key), in declaration order.
std::vector<CanStream> background_streams(const CanSegmentProperties& bus);
// Sum of C/T over the background frames.
double background_utilization(const CanSegmentProperties& bus);

// How much one background frame delays one of the gateway's frames.
struct BackgroundDelay {
  std::string name;
  std::uint32_t can_id = 0;
  bool extended = false;
  Nanos delay{0};         // interference in the queuing delay, or the blocking
  bool blocking = false;  // it loses arbitration but may hold the bus when the frame is queued
  friend bool operator==(const BackgroundDelay&, const BackgroundDelay&) = default;
};

// The background frames that delay `stream` (a gateway frame on `bus`) most, longest first, at most
// `top`: each higher-priority frame by its releases in the queuing delay w = R - J - C (or in
// `horizon` when R is unbounded), and the longest lower-priority frame by its blocking.
// `streams` is background_streams(bus), computed once by the caller.
std::vector<BackgroundDelay> dominant_background(const CanSegmentProperties& bus, std::span<const CanStream> streams,
                                                 const CanStream& stream, std::optional<Nanos> response, Nanos horizon,
                                                 std::size_t top);

}  // namespace cosmic
