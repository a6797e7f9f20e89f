// The etag binding protocol on the bus, gateway as broker (FAMOUSO-compatible layout; see
// docs/can-wire-format.md "Binding frames"). Pure functions.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

namespace cosmic::can_binding {

// Priority of binding frames: FAMOUSO's non-real-time level (inside our NRT band 0xF0-0xFF), so
// the binding protocol never competes with admitted HRT/SRT traffic.
inline constexpr std::uint8_t kPriority = 0xFD;
inline constexpr std::size_t kFrameBytes = 8;

struct GetEtagRequest {
  std::uint8_t requester = 0;  // TxNode of the asking node
  std::uint64_t subject = 0;
};

// A GET_ETAG request from its 29-bit identifier and data; nullopt when it is not one (wrong etag
// or not exactly 8 data bytes).
std::optional<GetEtagRequest> decode_get_etag(std::uint32_t can_id, std::span<const std::uint8_t> data);

// Data of a GET_ETAG request (the subject, big-endian).
std::array<std::uint8_t, kFrameBytes> get_etag_data(std::uint64_t subject);

// The two SUPPLY_ETAG answer frames: [requester, 0|1, etag high, etag low, subject bytes 0-3 | 4-7].
std::array<std::array<std::uint8_t, kFrameBytes>, 2> supply_etag_data(std::uint8_t requester, std::uint16_t etag,
                                                                      std::uint64_t subject);
// Identifier of the answer frames sent by the gateway with TxNode `gateway_node`.
std::uint32_t supply_etag_id(std::uint8_t gateway_node);

// FAMOUSO profile: the same two frames on etag 4 (SUPPLY_ETAG_NEW_BP), sent the way FAMOUSO's
// broker sends them (TxNode 0x7F, priority 0x7D in the 7-bit layout). FAMOUSO's client ignores
// byte 0 and takes the etag from frame 1 once both subject halves matched its request.
std::uint32_t supply_etag_new_bp_id();

struct SupplyEtag {
  std::uint8_t requester = 0;
  std::uint8_t part = 0;  // 0: subject bytes 0-3, 1: bytes 4-7
  std::uint16_t etag = 0;
  std::array<std::uint8_t, 4> subject_part{};
};
std::optional<SupplyEtag> decode_supply_etag(std::span<const std::uint8_t> data);

}  // namespace cosmic::can_binding
