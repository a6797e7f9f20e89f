#include "famouso_ccp.hpp"

#include "cosmic/can_wire.hpp"

namespace cosmic::famouso {
namespace {

// CCP's view of the identifier: etag (13..0), UID nibble (17..14), stage (21..18).
constexpr unsigned kNibbleShift = 14;
constexpr unsigned kStageShift = 18;

std::uint64_t uid_value(const std::array<std::uint8_t, 8>& uid) {
  std::uint64_t v = 0;
  for (const std::uint8_t b : uid) v = (v << 8) | b;
  return v;
}

}  // namespace

std::optional<CcpRequest> decode_ccp_request(std::uint32_t can_id) {
  if ((can_id & 0x3FFF) != kEtagCcpRsi) return std::nullopt;
  return CcpRequest{static_cast<std::uint8_t>((can_id >> kStageShift) & 0xF),
                    static_cast<std::uint8_t>((can_id >> kNibbleShift) & 0xF)};
}

std::uint32_t encode_ccp_request(std::uint8_t stage, std::uint8_t nibble) {
  return (static_cast<std::uint32_t>(kFamousoProtocolPriority) << 22) |
         (static_cast<std::uint32_t>(stage & 0xF) << kStageShift) |
         (static_cast<std::uint32_t>(nibble & 0xF) << kNibbleShift) | kEtagCcpRsi;
}

CcpBroker::CcpBroker(Nanos round_timeout) : round_timeout_(round_timeout) {}

void CcpBroker::reserve(std::uint8_t tx_node) { reserved_[tx_node & 0x7F] = true; }

std::optional<CcpFrame> CcpBroker::on_request(std::uint32_t can_id, Nanos now) {
  const auto request = decode_ccp_request(can_id);
  if (!request || request->stage != stage_) return std::nullopt;
  const std::uint8_t stage = request->stage;
  // Stage 15 is the high nibble of UID byte 0, stage 0 the low nibble of byte 7; the stage
  // rides in the low nibble of byte 7 until the last round fills it.
  if (stage == kCcpFirstStage) uid_ = {};
  uid_[7] = static_cast<std::uint8_t>((uid_[7] & 0xF0) | stage);
  std::uint8_t& byte = uid_[7 - stage / 2];
  byte =
      static_cast<std::uint8_t>(stage % 2 ? (byte & 0x0F) | (request->nibble << 4) : (byte & 0xF0) | request->nibble);
  last_round_ = now;
  if (stage > 0) {
    --stage_;
    return answer(kFamousoBrokerNode);
  }
  stage_ = kCcpFirstStage;
  const std::uint8_t node = assign(uid_value(uid_));
  if (node == kFamousoBrokerNode) return std::nullopt;  // all taken: the node keeps waiting
  return answer(node);
}

std::optional<CcpFrame> CcpBroker::expire(Nanos now) {
  if (stage_ == kCcpFirstStage || now - last_round_ < round_timeout_) return std::nullopt;
  stage_ = kCcpFirstStage;
  uid_ = {};
  return answer(kFamousoBrokerNode);  // all-zero data: "start over"
}

std::optional<Nanos> CcpBroker::deadline() const {
  if (stage_ == kCcpFirstStage) return std::nullopt;
  return last_round_ + round_timeout_;
}

// A node that starts again (after a reset) gets the TxNode it had; a new one the highest free
// TxNode below 0x7F that is not the gateway's (FAMOUSO's broker hands them out the same way).
std::uint8_t CcpBroker::assign(std::uint64_t uid) {
  for (std::uint8_t n = 0; n < kFamousoBrokerNode; ++n) {
    if (nodes_[n] == uid && uid != 0 && !reserved_[n]) return n;
  }
  for (int n = kFamousoBrokerNode - 1; n >= 0; --n) {
    if (reserved_[n] || nodes_[n] != 0) continue;
    nodes_[n] = uid == 0 ? ~0ull : uid;  // UID 0 is not used by FAMOUSO nodes; keep the slot taken anyway
    exhausted_ = false;
    return static_cast<std::uint8_t>(n);
  }
  exhausted_ = true;
  return kFamousoBrokerNode;
}

CcpFrame CcpBroker::answer(std::uint8_t tx_node) const {
  CcpFrame f;
  f.can_id = encode_famouso_id(FamousoIdentifier{kFamousoProtocolPriority, false, tx_node, kEtagCcpSsi});
  f.data = uid_;
  return f;
}

}  // namespace cosmic::famouso
