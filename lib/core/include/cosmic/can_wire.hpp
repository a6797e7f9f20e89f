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
inline constexpr std::uint32_t kEtagMask = 0x3FFF;          // the etag bits of an extended identifier
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

// --- FAMOUSO profile (docs/can-wire-format.md, "FAMOUSO profile"): FAMOUSO's little-endian PC
// layout, priority (7 bits, 28..22) | fragment flag (21) | TxNode (20..14) | etag (13..0).
// TxNode and etag sit where they sit in our layout, so decode_can_id() reads them for both.
struct FamousoIdentifier {
  std::uint8_t priority = 0;  // 7 bits
  bool fragment = false;      // the frame carries an AFP fragment
  std::uint8_t tx_node = 0;   // 7 bits
  std::uint16_t etag = 0;     // 14 bits
  friend bool operator==(const FamousoIdentifier&, const FamousoIdentifier&) = default;
};
std::uint32_t encode_famouso_id(const FamousoIdentifier& id);
FamousoIdentifier decode_famouso_id(std::uint32_t can_id);

// Class bands in 7 bits. HRT keeps all 16 levels of our band; SRT gets 0x10-0x77 (104 levels);
// NRT 0x78-0x7F holds FAMOUSO's own level (its nodes send everything with prio(0xFD) = 0x7D).
inline constexpr PriorityBand kFamousoHrtBand{0x00, 0x0F};
inline constexpr PriorityBand kFamousoSrtBand{0x10, 0x77};
inline constexpr PriorityBand kFamousoNrtBand{0x78, 0x7F};
inline constexpr std::uint8_t kFamousoProtocolPriority = 0x7D;  // FAMOUSO's prio(0xFD) in 7 bits
inline constexpr std::uint8_t kFamousoBrokerNode = 0x7F;        // TxNode of FAMOUSO's brokers
inline constexpr std::uint32_t kFamousoFragmentFlag = 1u << 21;
// FAMOUSO nodes send their events with kFamousoProtocolPriority, whatever the channel's class,
// and a TxNode from the CCP broker (0x7E downwards): admission analyses a channel a FAMOUSO node
// publishes at that priority, as the last TxNode of that level (the latest its frames can win).
inline constexpr std::uint8_t kFamousoLastAssignedNode = 0x7E;

// Admission's 8-bit priority (band_priority) in 7 bits: order-preserving, the class stays in its
// band, and distinct levels stay distinct while a band has room (HRT 16, SRT 104, NRT 8 channels).
std::uint8_t famouso_priority(std::uint8_t priority);
// An identifier in our layout (section 1) carried over to FAMOUSO's: priority through
// famouso_priority(), TxNode and etag unchanged.
std::uint32_t famouso_id_of(std::uint32_t cosmic_can_id, bool fragment);

inline constexpr std::uint16_t kEtagCcpSsi = 0;           // CCP: broker -> node
inline constexpr std::uint16_t kEtagCcpRsi = 1;           // CCP: node -> broker
inline constexpr std::uint16_t kEtagSupplyEtagNewBp = 4;  // FAMOUSO's binding answers
// Where a FAMOUSO segment's "SUBSCRIBE" subject lives: a protocol etag (5..100), so it never takes
// an etag admission hands out.
inline constexpr std::uint16_t kEtagFamousoSubscribe = 5;
inline constexpr std::uint64_t kFamousoSubscribeSubject = 0x5355425343524942ull;  // "SUBSCRIB"

// NRT events larger than one frame travel as fragments, each starting with a 2-byte header.
inline constexpr std::uint32_t kFragmentHeaderBytes = 2;
inline constexpr std::uint32_t kMaxFragments = 2048;

// Frames one event of `payload` bytes needs when a frame carries `frame_capacity` bytes.
std::uint32_t fragments_needed(std::uint64_t payload, std::uint32_t frame_capacity);

}  // namespace cosmic
