// The COSMIC/FAMOUSO layout of CAN identifiers and the constants of our CAN wire format
// (docs/can-wire-format.md is the normative description). Pure functions.
#pragma once

#include <cstdint>

#include "cosmic/model.hpp"

namespace cosmic {

// 29-bit extended identifier: priority (bits 28..21) | TxNode (20..14) | etag (13..0).
struct CanIdentifier {
  std::uint8_t priority = 0;
  std::uint8_t tx_node = 0;  // 7 bits
  std::uint16_t etag = 0;    // 14 bits
  friend bool operator==(const CanIdentifier&, const CanIdentifier&) = default;
};

std::uint32_t encode_can_id(const CanIdentifier& id);
CanIdentifier decode_can_id(std::uint32_t can_id);

inline constexpr std::uint16_t kMaxEtag = 16383;
inline constexpr std::uint16_t kHighestReservedEtag = 100;  // 0..100 belong to protocols
inline constexpr std::uint16_t kEtagGetEtag = 2;
inline constexpr std::uint16_t kEtagSupplyEtag = 3;
inline constexpr std::uint8_t kMaxTxNode = 127;

// Priority bands (8-bit priority field, lower wins arbitration).
struct PriorityBand {
  std::uint8_t first;
  std::uint8_t last;
};
inline constexpr PriorityBand kHrtBand{0x00, 0x0F};
inline constexpr PriorityBand kSrtBand{0x10, 0xEF};
inline constexpr PriorityBand kNrtBand{0xF0, 0xFF};
PriorityBand band_of(ChannelClass cls);

// Priority of the rank-th channel (0 = shortest deadline) of `count` channels in one band:
// one level each while the band has room, otherwise ranks are spread evenly over the band.
std::uint8_t band_priority(ChannelClass cls, std::size_t rank, std::size_t count);

// NRT events larger than one frame travel as fragments, each starting with a 2-byte header.
inline constexpr std::uint32_t kFragmentHeaderBytes = 2;
inline constexpr std::uint32_t kMaxFragments = 2048;

// Frames one event of `payload` bytes needs when a frame carries `frame_capacity` bytes.
std::uint32_t fragments_needed(std::uint64_t payload, std::uint32_t frame_capacity);

}  // namespace cosmic
