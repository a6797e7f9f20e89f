// How much a CAN bus can carry in a given time, and what cosmicd buffers for it. Pure.
//
// A frame lost in a burst is lost for good (classic CAN applications rarely repeat), and the
// kernel's cangw, which forwards in the receive path, loses none. A user-space forwarder loses
// frames wherever its buffers are smaller than what the bus delivers while one of its threads is
// held off its CPU. So cosmicd sizes its buffers for the bus, not for what is bound now: every
// frame the bus can carry (at its shortest frame) during kCanHold, in the receive socket
// (receive_buffer.hpp of the CAN adapter) and in each SRT and NRT egress lane to a CAN segment.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>

#include "cosmic/model.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

// How long a receive or lane thread may be held off its CPU without losing a frame.
inline constexpr Nanos kCanHold = std::chrono::milliseconds(250);
// The shortest frame on the wire: a classic data frame with an 11-bit identifier and no data,
// without stuff bits, plus the interframe space (44 + 3 bits). A CAN FD frame spends at least as
// many bits at the nominal rate before its data phase, so this bounds the frame rate of both.
inline constexpr std::uint32_t kShortestFrameBits = 47;

// Frames the bus can carry in `span`, at its shortest frame (rounded up).
inline std::size_t can_frames_within(const CanSegmentProperties& can, Nanos span) {
  const double frames_per_second = static_cast<double>(can.bitrate.bits_per_second) / kShortestFrameBits;
  return static_cast<std::size_t>(frames_per_second * static_cast<double>(span.count()) / 1e9 + 0.999);
}

// The least depth of each SRT and NRT egress lane to `segment` (Router::set_segment; HRT lanes
// keep their class depth): on CAN, the frames its bus carries in kCanHold
// (a burst forwarded from an equally fast bus fits while the lane thread is held); elsewhere 0
// (the configured class depth stands).
inline std::size_t egress_lane_floor(const SegmentSpec& segment) {
  return segment.type == SegmentType::can ? can_frames_within(segment.can, kCanHold) : 0;
}

}  // namespace cosmic
