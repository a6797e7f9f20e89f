// LCM segment adapter: LCM's UDP multicast protocol (SegmentSpec::lcm.url) spoken by the gateway
// itself, one receive socket and thread per segment and one transmit socket per channel class;
// messages beyond one datagram go in LCM's fragments both ways (up to the segment's
// max_message_size). A memq:// segment has no socket: what it sends reaches no one.
//
// LCM channel name = COSMIC channel name, or the one a native binding names
// (ChannelSpec::native: `{channel: NAME}`, always raw). Per channel (ChannelSpec::lcm_encoding):
//   envelope  the cosmic::envelope type (lib/adapters/lcm/types/cosmic_envelope.lcm, generated
//             by lcm-gen at build time) carrying the event header and the payload;
//   raw       the payload bytes unchanged, so native LCM programs, lcm-logger and lcm-spy see
//             their own type; inbound raw messages become events with origin 0, sequence 0,
//             age 0 and the channel's subject, marked for the router's fingerprint loop guard.
// The adapter never delivers its own publications (EventSink::on_problem(own_echo) instead).
#pragma once

#include <memory>

#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic {

// Never throws for a bad specification: errors surface through start()/configure() and health().
std::unique_ptr<SegmentAdapter> make_lcm_adapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log);

}  // namespace cosmic
