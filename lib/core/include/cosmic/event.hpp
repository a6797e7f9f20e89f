// Events as they cross the gateway. Views only: the bytes belong to whoever hands the view over
// and stay valid for the duration of the call that receives it.
#pragma once

#include <cstdint>
#include <span>

#include "cosmic/units.hpp"

namespace cosmic {

// Stable identifier of a bound channel inside one cosmicd process (never reused while it runs).
using ChannelId = std::uint32_t;
inline constexpr ChannelId kNoChannel = 0xFFFFFFFF;

// Envelope fields carried on IP segments (DESIGN.md section 6). Events from native sources
// (a CAN device, a raw LCM publisher) have origin 0, sequence 0 and age 0.
struct EventHeader {
  std::uint64_t subject = 0;
  std::uint64_t origin = 0;    // id of the gateway that first forwarded the event, 0 = native source
  std::uint32_t sequence = 0;  // per origin and channel, starts at 1
  std::uint8_t hop_count = 0;  // gateways crossed so far
  std::int64_t created_ns = 0; // creation time on the origin's clock (informational, no clock sync)
  std::int64_t age_ns = 0;     // time already spent in transit when it reached this gateway
};

// Handed by an adapter to the router (adapter thread).
struct InboundEvent {
  ChannelId channel = kNoChannel;
  EventHeader header;
  std::span<const std::uint8_t> payload;
  Nanos received_at{0};  // steady clock when the adapter got it
  // Set by a wire format that carries no origin or sequence on a network that can hand a copy the
  // gateway forwarded back to it (raw LCM: two gateways bridging one group in opposite directions).
  // The router then cuts loops by payload fingerprint (RawLoopGuard). A native CAN frame needs
  // none: an identifier has one sender, and CAN_RAW does not return a socket's own frames.
  bool guard_loops_by_fingerprint = false;
};

// Handed by the router to an adapter (router thread).
struct OutboundEvent {
  ChannelId channel = kNoChannel;
  EventHeader header;  // age already includes the residence time in this gateway
  std::span<const std::uint8_t> payload;
};

// Largest hop count an event may carry; beyond it the event is a loop and is dropped.
inline constexpr std::uint8_t kMaxHops = 8;

}  // namespace cosmic
