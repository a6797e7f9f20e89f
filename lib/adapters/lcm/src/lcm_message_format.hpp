// The wire formats of LCM channels, one per binding (DESIGN.md section 7), after the DDS adapter's
// sample formats: the envelope (this project's header, then the contents; cosmic/lcm_wire.hpp)
// and raw (the contents alone, as the LCM channel's own type carries them: a native binding or
// `encoding: raw`). The transport (lcm_adapter.cpp, lcm_transmit.cpp) reads and writes whole
// messages; a format turns one into an event and an event into the parts of one, and says what it
// carries of an event's identity. Internal to the LCM adapter; fuzzed by fuzz/lcm_*_fuzzer.cpp.
//
// Threads: a format is immutable; the receive thread and the egress lanes share it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "cosmic/event.hpp"
#include "cosmic/lcm_wire.hpp"
#include "cosmic/model.hpp"

namespace cosmic::lcm_detail {

// What the receiving side knows of a message beside its bytes, for formats that carry less.
struct LcmArrival {
  std::uint64_t subject = 0;     // the channel's subject
  std::int64_t realtime_ns = 0;  // when the kernel took it (wall clock, informational)
};

// The parts of one message, in order: at most a header and the contents.
inline constexpr std::size_t kLcmMessageParts = 2;
using LcmMessageParts = std::array<std::span<const std::uint8_t>, kLcmMessageParts>;
using LcmHeaderBuffer = std::array<std::uint8_t, kLcmEnvelopeHeaderSize>;

class LcmMessageFormat {
 public:
  virtual ~LcmMessageFormat() = default;
  virtual LcmEncoding encoding() const noexcept = 0;
  // What the format carries of an event's identity (the router asks it: InboundEvent::identity).
  virtual FormatIdentity identity() const noexcept = 0;
  // One whole message into `event`: its header and its contents, a view into `message`. False
  // when the message is not one event of this format with at most `max_payload` bytes of contents.
  virtual bool decode(std::span<const std::uint8_t> message, const LcmArrival& arrival, std::uint64_t max_payload,
                      InboundEvent& event) const = 0;
  // The parts of the message carrying `event` (a header goes into `header`); their count, 0 when
  // the event cannot be carried in this format.
  virtual std::size_t encode(const OutboundEvent& event, LcmHeaderBuffer& header, LcmMessageParts& parts) const = 0;
};

std::shared_ptr<const LcmMessageFormat> make_lcm_message_format(LcmEncoding encoding);

}  // namespace cosmic::lcm_detail
