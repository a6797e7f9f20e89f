// Events as they cross the gateway. Views only: the bytes belong to whoever hands the view over
// and stay valid for the duration of the call that receives it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "cosmic/channel_class.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

// Stable identifier of a bound channel inside one cosmicd process (never reused while it runs).
using ChannelId = std::uint32_t;
inline constexpr ChannelId kNoChannel = 0xFFFFFFFF;

// Envelope fields carried on IP segments (DESIGN.md section 6). Events from native sources
// (a CAN device, a raw LCM publisher) have origin 0, sequence 0 and age 0.
struct EventHeader {
  std::uint64_t subject = 0;
  std::uint64_t origin = 0;     // id of the gateway that first forwarded the event, 0 = native source
  std::uint32_t sequence = 0;   // per origin and channel, starts at 1
  std::uint8_t hop_count = 0;   // gateways crossed so far
  std::int64_t created_ns = 0;  // creation time on the origin's clock (informational, no clock sync)
  std::int64_t age_ns = 0;      // time already spent in transit when it reached this gateway
};

// What a wire format carries of an event's identity, as the format unit says (envelopes: all of
// it; raw LCM, native CAN, opaque DDS: none). The router asks it rather than the transport.
struct FormatIdentity {
  bool origin = true;     // who made the event (a gateway or a component)
  bool sequence = true;   // its number from that origin
  bool hop_count = true;  // how many gateways it crossed
  // A copy the gateway forwarded can come back to it in this format (raw LCM: two gateways
  // bridging one group in opposite directions). A native CAN frame cannot: an identifier has one
  // sender, and CAN_RAW does not return a socket's own frames.
  bool echoes_back = false;
  // Without an origin to tell, the router cuts such loops by payload fingerprint (RawLoopGuard).
  constexpr bool needs_fingerprint_loop_guard() const noexcept { return !origin && echoes_back; }
  friend bool operator==(const FormatIdentity&, const FormatIdentity&) = default;
};

// Handed by an adapter to the router (adapter thread).
struct InboundEvent {
  ChannelId channel = kNoChannel;
  EventHeader header;
  std::span<const std::uint8_t> payload;
  Nanos received_at{0};  // steady clock when the adapter got it
  // What the wire format it came in carries of its identity; the router's loop and duplicate
  // checks ask it (see FormatIdentity).
  FormatIdentity identity{};
  // Set by an adapter whose receive threads each carry the channels of one class only (DDS: a
  // participant per class) to that class. The router may then hand an event of that class to its
  // egress transport on this very thread when the egress lane is idle, sparing the wake-up of the
  // lane's thread (EgressLane::push_or_send): a thread that also carries a higher class must
  // never wait for a lower class's send, so unset (CAN, LCM: one receive thread for every class)
  // every event waits for its lane's thread.
  std::optional<ChannelClass> receiver_class{};
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
