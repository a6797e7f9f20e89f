#include "cosmic/lcm_udpm.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace cosmic {
namespace {

std::uint32_t read_u32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]};
}

std::uint16_t read_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }

void write_u32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}

void write_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}

// The NUL-terminated channel at the start of `bytes`: its length without the NUL, or nullopt
// when there is none of 1..kLcmMaxChannelBytes bytes.
std::optional<std::size_t> channel_length(std::span<const std::uint8_t> bytes) {
  const std::size_t limit = std::min(bytes.size(), kLcmMaxChannelBytes + 1);
  const void* nul = std::memchr(bytes.data(), 0, limit);
  if (nul == nullptr) return std::nullopt;
  const auto length = static_cast<std::size_t>(static_cast<const std::uint8_t*>(nul) - bytes.data());
  if (length == 0) return std::nullopt;
  return length;
}

std::optional<LcmDatagram> parse_short(std::span<const std::uint8_t> bytes) {
  const auto rest = bytes.subspan(kLcmShortHeaderSize);
  const auto length = channel_length(rest);
  if (!length) return std::nullopt;
  LcmDatagram out;
  out.sequence = read_u32(bytes.data() + 4);
  out.channel = std::string_view(reinterpret_cast<const char*>(rest.data()), *length);
  out.data = rest.subspan(*length + 1);
  out.message_size = static_cast<std::uint32_t>(out.data.size());
  return out;
}

std::optional<LcmDatagram> parse_fragment(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kLcmFragmentHeaderSize) return std::nullopt;
  const std::uint8_t* p = bytes.data();
  LcmDatagram out;
  out.fragment = true;
  out.sequence = read_u32(p + 4);
  out.message_size = read_u32(p + 8);
  out.fragment_offset = read_u32(p + 12);
  out.fragment_no = read_u16(p + 16);
  out.fragment_count = read_u16(p + 18);
  if (out.fragment_no >= out.fragment_count) return std::nullopt;
  auto rest = bytes.subspan(kLcmFragmentHeaderSize);
  if (out.fragment_no == 0) {
    if (out.fragment_offset != 0) return std::nullopt;
    const auto length = channel_length(rest);
    if (!length) return std::nullopt;
    out.channel = std::string_view(reinterpret_cast<const char*>(rest.data()), *length);
    rest = rest.subspan(*length + 1);
  }
  out.data = rest;
  // The slice lies inside the message (64-bit sums: no wrap).
  if (std::uint64_t{out.fragment_offset} + out.data.size() > out.message_size) return std::nullopt;
  return out;
}

}  // namespace

std::optional<LcmDatagram> parse_lcm_datagram(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kLcmShortHeaderSize || bytes.size() > kLcmMaxDatagram) return std::nullopt;
  const std::uint32_t magic = read_u32(bytes.data());
  if (magic == kLcmShortMagic) return parse_short(bytes);
  if (magic == kLcmFragmentMagic) return parse_fragment(bytes);
  return std::nullopt;
}

std::array<std::uint8_t, kLcmShortHeaderSize> lcm_short_header(std::uint32_t sequence) {
  std::array<std::uint8_t, kLcmShortHeaderSize> out{};
  write_u32(out.data(), kLcmShortMagic);
  write_u32(out.data() + 4, sequence);
  return out;
}

std::array<std::uint8_t, kLcmFragmentHeaderSize> lcm_fragment_header(std::uint32_t sequence, std::uint32_t message_size,
                                                                     std::uint32_t fragment_offset,
                                                                     std::uint16_t fragment_no,
                                                                     std::uint16_t fragment_count) {
  std::array<std::uint8_t, kLcmFragmentHeaderSize> out{};
  write_u32(out.data(), kLcmFragmentMagic);
  write_u32(out.data() + 4, sequence);
  write_u32(out.data() + 8, message_size);
  write_u32(out.data() + 12, fragment_offset);
  write_u16(out.data() + 16, fragment_no);
  write_u16(out.data() + 18, fragment_count);
  return out;
}

std::optional<LcmSendPlan> plan_lcm_message(std::size_t channel_size, std::size_t payload_size) {
  if (channel_size == 0 || channel_size > kLcmMaxChannelBytes) return std::nullopt;
  if (payload_size > std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
  const std::size_t total = channel_size + 1 + payload_size;
  if (total <= kLcmShortMessageMax) return LcmSendPlan{0, payload_size};
  const std::size_t count = total / kLcmFragmentMaxData + (total % kLcmFragmentMaxData != 0 ? 1 : 0);
  if (count > std::numeric_limits<std::uint16_t>::max()) return std::nullopt;
  return LcmSendPlan{static_cast<std::uint16_t>(count), kLcmFragmentMaxData - (channel_size + 1)};
}

}  // namespace cosmic
