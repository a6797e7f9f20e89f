// LCM's UDP multicast datagrams (the "udpm" provider's wire format), as bytes: what the LCM
// adapter's own transport sends and parses, so no liblcm reader thread and notification pipe
// sit between the socket and the gateway (issue 20, item 5). Pure functions, no I/O; any thread.
// Fuzzed by fuzz/lcm_udpm_fuzzer.cpp; interoperation with liblcm is tested over real sockets
// (tests/integration/lcm).
//
// Layout, big-endian (LCM UDP Multicast Protocol Description; liblcm 1.x on Linux):
//   short message, one datagram:  "LC02" magic, uint32 sequence, channel, NUL, payload
//   fragment of a long message:   "LC03" magic, uint32 sequence, uint32 message size (payload
//                                 bytes only), uint32 fragment offset (into the payload),
//                                 uint16 fragment number, uint16 fragment count; fragment 0 then
//                                 carries channel, NUL and the first slice, the others a slice.
// A sender uses a short message while channel + NUL + payload fit in kLcmShortMessageMax bytes,
// else fragments of at most kLcmFragmentMaxData bytes after the header (fragment 0 counting its
// channel and NUL); a receiver keys a message being reassembled by sender address and sequence.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace cosmic {

inline constexpr std::uint32_t kLcmShortMagic = 0x4c433032;     // "LC02"
inline constexpr std::uint32_t kLcmFragmentMagic = 0x4c433033;  // "LC03"
inline constexpr std::size_t kLcmShortHeaderSize = 8;
inline constexpr std::size_t kLcmFragmentHeaderSize = 20;
// liblcm's limits on Linux: both make a datagram of at most 65,507 bytes, IPv4's UDP maximum.
inline constexpr std::size_t kLcmShortMessageMax = 65499;  // channel + NUL + payload
inline constexpr std::size_t kLcmFragmentMaxData = 65487;  // bytes after a fragment's header
inline constexpr std::size_t kLcmMaxDatagram = kLcmFragmentHeaderSize + kLcmFragmentMaxData;
inline constexpr std::size_t kLcmMaxChannelBytes = 63;  // LCM_MAX_CHANNEL_NAME_LENGTH

// One parsed datagram. Spans point into the parsed bytes.
struct LcmDatagram {
  bool fragment = false;
  std::uint32_t sequence = 0;
  std::string_view channel;  // empty for fragments after the first
  // Fragments only: the whole message's payload size, where `data` starts in it, which
  // fragment of how many this is.
  std::uint32_t message_size = 0;
  std::uint32_t fragment_offset = 0;
  std::uint16_t fragment_no = 0;
  std::uint16_t fragment_count = 0;
  std::span<const std::uint8_t> data;  // the payload (short) or this fragment's slice
};

// `bytes` as one LCM datagram; nullopt when it is not one (unknown magic, no NUL-terminated
// channel of 1..kLcmMaxChannelBytes bytes where one belongs, a fragment whose slice does not lie
// inside its message or whose number is not below its count).
std::optional<LcmDatagram> parse_lcm_datagram(std::span<const std::uint8_t> bytes);

// Headers to send (big-endian, as above).
std::array<std::uint8_t, kLcmShortHeaderSize> lcm_short_header(std::uint32_t sequence);
std::array<std::uint8_t, kLcmFragmentHeaderSize> lcm_fragment_header(std::uint32_t sequence, std::uint32_t message_size,
                                                                     std::uint32_t fragment_offset,
                                                                     std::uint16_t fragment_no,
                                                                     std::uint16_t fragment_count);

// How a message of `payload_size` bytes on a channel of `channel_size` bytes goes out: one short
// datagram (fragment_count 0), or fragment_count fragments of which the first carries
// first_slice payload bytes and the others up to kLcmFragmentMaxData each. nullopt when it cannot
// be sent at all (no channel, a channel too long, more than 65,535 fragments or a message size
// beyond uint32).
struct LcmSendPlan {
  std::uint16_t fragment_count = 0;
  std::size_t first_slice = 0;
};
std::optional<LcmSendPlan> plan_lcm_message(std::size_t channel_size, std::size_t payload_size);

}  // namespace cosmic
