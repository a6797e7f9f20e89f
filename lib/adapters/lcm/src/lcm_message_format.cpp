#include "lcm_message_format.hpp"

#include <cstdint>

namespace cosmic::lcm_detail {
namespace {

// This project's envelope: the whole event header travels with the contents.
class EnvelopeFormat final : public LcmMessageFormat {
 public:
  LcmEncoding encoding() const noexcept override { return LcmEncoding::envelope; }
  FormatIdentity identity() const noexcept override { return FormatIdentity{}; }

  bool decode(std::span<const std::uint8_t> message, const LcmArrival&, std::uint64_t max_payload,
              InboundEvent& event) const override {
    // Decoded in place: the contents stay in the receive buffer, no copy.
    const auto decoded = decode_lcm_envelope(message, max_payload);
    if (!decoded) return false;
    event.header = decoded->header;
    event.payload = decoded->payload;
    event.identity = identity();
    return true;
  }

  std::size_t encode(const OutboundEvent& event, LcmHeaderBuffer& header, LcmMessageParts& parts) const override {
    if (event.payload.size() > static_cast<std::size_t>(INT32_MAX) - kLcmEnvelopeHeaderSize) return 0;
    // The header goes out as given, as on DDS: the router stamps what this gateway originates
    // with its id, a component (libcosmic-client) stamps its own.
    header = encode_lcm_envelope_header(event.header, static_cast<std::uint32_t>(event.payload.size()));
    parts[0] = header;
    parts[1] = event.payload;
    return 2;
  }
};

// The contents alone: no origin, sequence or hop count, and a group two gateways bridge in
// opposite directions hands a forwarded copy back.
class RawFormat final : public LcmMessageFormat {
 public:
  LcmEncoding encoding() const noexcept override { return LcmEncoding::raw; }
  FormatIdentity identity() const noexcept override { return FormatIdentity{false, false, false, true}; }

  bool decode(std::span<const std::uint8_t> message, const LcmArrival& arrival, std::uint64_t max_payload,
              InboundEvent& event) const override {
    if (message.size() > max_payload) return false;
    event.header = EventHeader{};
    event.header.subject = arrival.subject;
    event.header.created_ns = arrival.realtime_ns;
    event.payload = message;
    event.identity = identity();
    return true;
  }

  std::size_t encode(const OutboundEvent& event, LcmHeaderBuffer&, LcmMessageParts& parts) const override {
    parts[0] = event.payload;
    return 1;
  }
};

}  // namespace

std::shared_ptr<const LcmMessageFormat> make_lcm_message_format(LcmEncoding encoding) {
  if (encoding == LcmEncoding::raw) return std::make_shared<RawFormat>();
  return std::make_shared<EnvelopeFormat>();
}

}  // namespace cosmic::lcm_detail
