// The broker side of FAMOUSO's CAN configuration protocol (CCP): a FAMOUSO node blocks at start
// until a broker gives it a TxNode. The node sends its 64-bit UID one nibble per round (stage 15
// down to 0) in the identifier of an empty frame on etag CCP_RSI; the broker answers every
// accepted round on etag CCP_SSI with the UID nibbles known so far (the stage in the last data
// byte's low nibble) as TxNode 0x7F, and the last round with the node's new TxNode. Several
// nodes starting together are told apart by CAN arbitration: the broker follows the first
// frame of a round and the others see a UID that is not theirs and start over.
// Pure code: the CAN adapter's receive thread owns one per FAMOUSO segment.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "cosmic/units.hpp"

namespace cosmic::famouso {

inline constexpr std::uint8_t kCcpFirstStage = 15;

struct CcpFrame {
  std::uint32_t can_id = 0;  // 29 bits
  std::array<std::uint8_t, 8> data{};
};

// Stage and UID nibble of a CCP_RSI identifier; nullopt when the identifier is not one.
struct CcpRequest {
  std::uint8_t stage = 0;
  std::uint8_t nibble = 0;
};
std::optional<CcpRequest> decode_ccp_request(std::uint32_t can_id);
std::uint32_t encode_ccp_request(std::uint8_t stage, std::uint8_t nibble);  // what a node sends

class CcpBroker {
 public:
  explicit CcpBroker(Nanos round_timeout = Nanos(500'000'000));

  // A TxNode never given out: the gateway's own (0x7F, FAMOUSO's broker, never is either).
  void reserve(std::uint8_t tx_node);

  // A CCP_RSI frame: the answer to send, or nullopt for a frame of another round (the node
  // lost arbitration and waits) or when every TxNode is taken (counted by the caller).
  std::optional<CcpFrame> on_request(std::uint32_t can_id, Nanos now);
  // A node that stopped in the middle of its rounds holds up every other node: after
  // round_timeout without its next frame the broker starts over and tells the waiting nodes so
  // with an all-zero answer.
  std::optional<CcpFrame> expire(Nanos now);
  std::optional<Nanos> deadline() const;

  bool exhausted() const { return exhausted_; }  // the last assignment failed: all TxNodes taken

 private:
  std::uint8_t assign(std::uint64_t uid);
  CcpFrame answer(std::uint8_t tx_node) const;

  Nanos round_timeout_;
  std::uint8_t stage_ = kCcpFirstStage;
  std::array<std::uint8_t, 8> uid_{};
  Nanos last_round_{0};
  std::array<std::uint64_t, 128> nodes_{};  // TxNode -> UID, 0 = free
  std::array<bool, 128> reserved_{};
  bool exhausted_ = false;
};

}  // namespace cosmic::famouso
