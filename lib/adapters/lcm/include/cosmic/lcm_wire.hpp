// The cosmic::envelope on LCM segments (lib/adapters/lcm/types/cosmic_envelope.lcm) as bytes:
// what the LCM adapter runs on every message of an `envelope` channel. Pure functions, no I/O;
// fuzzed by fuzz/lcm_envelope_fuzzer.cpp against the decoder lcm-gen generates.
//
// Layout, big-endian, exactly as lcm-gen encodes it:
//   offset  0  int64  type fingerprint (kLcmEnvelopeHash)
//           8  int64  subject        16 int64 origin     24 int32 sequence   28 int8 hop_count
//          29  int64  created_ns     37 int64 age_ns     45 int32 payload_size
//          49  payload_size bytes
// A message is accepted only when it is exactly one envelope: the fingerprint matches,
// 0 <= payload_size <= the segment's max_message_size, and no byte is missing or left over.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "cosmic/event.hpp"

namespace cosmic {

// lcm-gen's fingerprint of cosmic.envelope (envelope::getHash(); checked by the LCM tests).
inline constexpr std::uint64_t kLcmEnvelopeHash = 0x94CEE8BEF1BC1684ull;
inline constexpr std::size_t kLcmEnvelopeHeaderSize = 8 + 8 + 8 + 4 + 1 + 8 + 8 + 4;  // 49
inline constexpr std::size_t kLcmEnvelopePayloadSizeOffset = kLcmEnvelopeHeaderSize - 4;

// A decoded envelope. `payload` points into the decoded bytes (no copy).
struct LcmEnvelope {
  EventHeader header;  // subject and origin are the int64 fields' two's complement
  std::span<const std::uint8_t> payload;
};

// One whole LCM message as an envelope; nullopt when it is not exactly one well-formed envelope
// with a payload of at most `max_payload` bytes.
std::optional<LcmEnvelope> decode_lcm_envelope(std::span<const std::uint8_t> bytes, std::uint64_t max_payload);

// The envelope's bytes before its payload, for an event of `payload_size` bytes (at most
// INT32_MAX; the adapter refuses larger ones before): the header and that payload, back to back,
// are one envelope exactly as lcm-gen encodes it.
std::array<std::uint8_t, kLcmEnvelopeHeaderSize> encode_lcm_envelope_header(const EventHeader& header,
                                                                            std::uint32_t payload_size);

}  // namespace cosmic
