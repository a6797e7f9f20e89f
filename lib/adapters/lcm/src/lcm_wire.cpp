#include "cosmic/lcm_wire.hpp"

#include <climits>

namespace cosmic {
namespace {

std::uint64_t read_be(const std::uint8_t* p, std::size_t bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

void write_be(std::uint8_t* p, std::uint64_t v, std::size_t bytes) {
  for (std::size_t i = bytes; i-- > 0;) {
    p[i] = static_cast<std::uint8_t>(v);
    v >>= 8;
  }
}

}  // namespace

std::array<std::uint8_t, kLcmEnvelopeHeaderSize> encode_lcm_envelope_header(const EventHeader& header,
                                                                            std::uint32_t payload_size) {
  std::array<std::uint8_t, kLcmEnvelopeHeaderSize> out{};
  std::uint8_t* p = out.data();
  write_be(p, kLcmEnvelopeHash, 8);
  write_be(p + 8, header.subject, 8);
  write_be(p + 16, header.origin, 8);
  write_be(p + 24, header.sequence, 4);
  p[28] = header.hop_count;
  write_be(p + 29, static_cast<std::uint64_t>(header.created_ns), 8);
  write_be(p + 37, static_cast<std::uint64_t>(header.age_ns), 8);
  write_be(p + kLcmEnvelopePayloadSizeOffset, payload_size, 4);
  return out;
}

std::optional<LcmEnvelope> decode_lcm_envelope(std::span<const std::uint8_t> bytes, std::uint64_t max_payload) {
  // LCM hands over at most an int's worth of bytes; anything longer is not ours to read.
  if (bytes.size() < kLcmEnvelopeHeaderSize || bytes.size() > static_cast<std::size_t>(INT_MAX)) return std::nullopt;
  const std::uint8_t* p = bytes.data();
  if (read_be(p, 8) != kLcmEnvelopeHash) return std::nullopt;
  // int32 on the wire: the sign bit set is a negative size.
  const std::uint64_t payload_size = read_be(p + kLcmEnvelopePayloadSizeOffset, 4);
  if (payload_size > static_cast<std::uint64_t>(INT32_MAX) || payload_size > max_payload ||
      bytes.size() - kLcmEnvelopeHeaderSize != payload_size)
    return std::nullopt;
  LcmEnvelope out;
  out.header.subject = read_be(p + 8, 8);
  out.header.origin = read_be(p + 16, 8);
  out.header.sequence = static_cast<std::uint32_t>(read_be(p + 24, 4));
  out.header.hop_count = p[28];
  out.header.created_ns = static_cast<std::int64_t>(read_be(p + 29, 8));
  out.header.age_ns = static_cast<std::int64_t>(read_be(p + 37, 8));
  out.payload = bytes.subspan(kLcmEnvelopeHeaderSize);
  return out;
}

}  // namespace cosmic
