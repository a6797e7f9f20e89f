#include "cosmic/can_wire.hpp"

namespace cosmic {

std::uint32_t encode_can_id(const CanIdentifier& id) {
  return (static_cast<std::uint32_t>(id.priority) << 21) | (static_cast<std::uint32_t>(id.tx_node & 0x7F) << 14) |
         static_cast<std::uint32_t>(id.etag & 0x3FFF);
}

CanIdentifier decode_can_id(std::uint32_t can_id) {
  return CanIdentifier{static_cast<std::uint8_t>((can_id >> 21) & 0xFF), static_cast<std::uint8_t>((can_id >> 14) & 0x7F),
                       static_cast<std::uint16_t>(can_id & 0x3FFF)};
}

PriorityBand band_of(ChannelClass cls) {
  switch (cls) {
    case ChannelClass::hrt: return kHrtBand;
    case ChannelClass::srt: return kSrtBand;
    case ChannelClass::nrt: return kNrtBand;
  }
  return kNrtBand;
}

std::uint8_t band_priority(ChannelClass cls, std::size_t rank, std::size_t count) {
  const PriorityBand band = band_of(cls);
  const std::size_t levels = static_cast<std::size_t>(band.last - band.first) + 1;
  const std::size_t offset = count <= levels ? rank : rank * levels / count;
  return static_cast<std::uint8_t>(band.first + offset);
}

std::uint32_t fragments_needed(std::uint64_t payload, std::uint32_t frame_capacity) {
  if (payload <= frame_capacity) return 1;
  const std::uint64_t per_fragment = frame_capacity - kFragmentHeaderBytes;
  return static_cast<std::uint32_t>((payload + per_fragment - 1) / per_fragment);
}

}  // namespace cosmic
