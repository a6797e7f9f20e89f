#include "can_binding.hpp"

#include "cosmic/can_wire.hpp"

namespace cosmic::can_binding {

std::optional<GetEtagRequest> decode_get_etag(std::uint32_t can_id, std::span<const std::uint8_t> data) {
  const CanIdentifier id = decode_can_id(can_id);
  if (id.etag != kEtagGetEtag || data.size() != kFrameBytes) return std::nullopt;
  std::uint64_t subject = 0;
  for (const std::uint8_t byte : data) subject = (subject << 8) | byte;
  return GetEtagRequest{id.tx_node, subject};
}

std::array<std::uint8_t, kFrameBytes> get_etag_data(std::uint64_t subject) {
  std::array<std::uint8_t, kFrameBytes> data{};
  for (std::size_t i = 0; i < kFrameBytes; ++i) data[i] = static_cast<std::uint8_t>(subject >> (8 * (7 - i)));
  return data;
}

std::array<std::array<std::uint8_t, kFrameBytes>, 2> supply_etag_data(std::uint8_t requester, std::uint16_t etag,
                                                                      std::uint64_t subject) {
  const auto subject_bytes = get_etag_data(subject);
  std::array<std::array<std::uint8_t, kFrameBytes>, 2> frames{};
  for (std::uint8_t part = 0; part < 2; ++part) {
    auto& f = frames[part];
    f[0] = static_cast<std::uint8_t>(requester & kMaxTxNode);
    f[1] = part;
    f[2] = static_cast<std::uint8_t>((etag >> 8) & 0x3F);
    f[3] = static_cast<std::uint8_t>(etag & 0xFF);
    for (std::size_t i = 0; i < 4; ++i) f[4 + i] = subject_bytes[std::size_t{4} * part + i];
  }
  return frames;
}

std::uint32_t supply_etag_id(std::uint8_t gateway_node) {
  return encode_can_id(CanIdentifier{kPriority, gateway_node, kEtagSupplyEtag});
}

std::uint32_t supply_etag_new_bp_id() {
  return encode_famouso_id(
      FamousoIdentifier{kFamousoProtocolPriority, false, kFamousoBrokerNode, kEtagSupplyEtagNewBp});
}

std::optional<SupplyEtag> decode_supply_etag(std::span<const std::uint8_t> data) {
  if (data.size() != kFrameBytes || data[1] > 1) return std::nullopt;
  SupplyEtag s;
  s.requester = data[0];
  s.part = data[1];
  s.etag = static_cast<std::uint16_t>(((data[2] & 0x3F) << 8) | data[3]);
  for (std::size_t i = 0; i < 4; ++i) s.subject_part[i] = data[4 + i];
  return s;
}

}  // namespace cosmic::can_binding
