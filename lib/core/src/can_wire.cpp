#include "cosmic/can_wire.hpp"

#include <algorithm>

namespace cosmic {

std::uint32_t encode_can_id(const CanIdentifier& id) {
  return (static_cast<std::uint32_t>(id.priority) << 21) | (static_cast<std::uint32_t>(id.tx_node & 0x7F) << 14) |
         static_cast<std::uint32_t>(id.etag & 0x3FFF);
}

CanIdentifier decode_can_id(std::uint32_t can_id) {
  return CanIdentifier{static_cast<std::uint8_t>((can_id >> 21) & 0xFF),
                       static_cast<std::uint8_t>((can_id >> 14) & 0x7F), static_cast<std::uint16_t>(can_id & 0x3FFF)};
}

std::uint32_t encode_famouso_id(const FamousoIdentifier& id) {
  return (static_cast<std::uint32_t>(id.priority & 0x7F) << 22) | (id.fragment ? 1u << 21 : 0u) |
         (static_cast<std::uint32_t>(id.tx_node & 0x7F) << 14) | static_cast<std::uint32_t>(id.etag & 0x3FFF);
}

FamousoIdentifier decode_famouso_id(std::uint32_t can_id) {
  return FamousoIdentifier{static_cast<std::uint8_t>((can_id >> 22) & 0x7F), ((can_id >> 21) & 1) != 0,
                           static_cast<std::uint8_t>((can_id >> 14) & 0x7F),
                           static_cast<std::uint16_t>(can_id & 0x3FFF)};
}

namespace {
// Level `offset` of a 7-bit band, the last level for everything beyond it.
std::uint8_t clamp_into(PriorityBand band, std::size_t offset) {
  return static_cast<std::uint8_t>(band.first + std::min<std::size_t>(offset, band.last - band.first));
}
}  // namespace

std::uint8_t famouso_priority(std::uint8_t priority) {
  if (priority <= kHrtBand.last) return clamp_into(kFamousoHrtBand, priority - kHrtBand.first);
  if (priority <= kSrtBand.last) return clamp_into(kFamousoSrtBand, priority - kSrtBand.first);
  return clamp_into(kFamousoNrtBand, priority - kNrtBand.first);
}

std::uint32_t famouso_id_of(std::uint32_t cosmic_can_id, bool fragment) {
  const CanIdentifier id = decode_can_id(cosmic_can_id);
  return encode_famouso_id(FamousoIdentifier{famouso_priority(id.priority), fragment, id.tx_node, id.etag});
}

PriorityBand band_of(ChannelClass cls) {
  switch (cls) {
    case ChannelClass::hrt:
      return kHrtBand;
    case ChannelClass::srt:
      return kSrtBand;
    case ChannelClass::nrt:
      return kNrtBand;
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
