// Validation of every inbound event's envelope against the channel it claims, before the router
// lets it near its arithmetic, its queues or its duplicate filter. Pure: no state, no I/O, no
// allocation; any thread may call it (the router calls it from adapter threads).
#pragma once

#include <cstdint>

#include "cosmic/event.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/router_stats.hpp"

namespace cosmic {

// Largest age an inbound event may claim. Time in transit is milliseconds, not hours: a larger
// value is corrupt or hostile. The bound keeps age + residence (and created = now - age) far
// from int64 overflow.
inline constexpr std::int64_t kMaxIngressAgeNs = 3'600'000'000'000;  // one hour

// Why an inbound event is refused; `none` lets it pass.
enum class IngressFault : std::uint8_t {
  none,
  negative_age,      // age_ns < 0
  age_beyond_bound,  // age_ns > kMaxIngressAgeNs
  foreign_subject,   // subject is not the channel's
  own_origin,        // claims to come from this gateway: a loop or a spoof
  hop_limit,         // hop_count >= kMaxHops: a loop between gateways
  oversize,          // payload larger than the channel's admitted `payload`
};

const char* to_string(IngressFault fault);

// Counter an ingress fault is reported under: invalid header fields are `invalid`, loop copies
// are `duplicate` (the event was forwarded before), an oversized payload is `oversize`.
DropReason drop_reason(IngressFault fault);

// Checks the header and payload size of `event`, received on channel `spec`, at gateway `self`.
// Checks run in a fixed order (size, subject, origin, hops, age) and the first failure is
// returned.
IngressFault ingress_check(const InboundEvent& event, const ChannelSpec& spec, const GatewayIdentity& self);

}  // namespace cosmic
