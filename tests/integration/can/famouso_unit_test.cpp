// The FAMOUSO profile's pure parts, checked against FAMOUSO's own rules (steup/FAMOUSO:
// canID_LE_PC.h, ccp/Client.h, etagBP/Client.h, afp/): identifier layout and priority bands,
// AFP headers and fragments, the CCP broker against a node that follows FAMOUSO's client, and
// the binding guards (rate limit, answer pacing).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "binding_guard.hpp"
#include "can_binding.hpp"
#include "cosmic/can_wire.hpp"
#include "famouso_afp.hpp"
#include "famouso_ccp.hpp"

namespace cosmic {
namespace {

using famouso::AfpFragmenter;
using famouso::AfpOutcome;
using famouso::AfpReassembler;

TEST(FamousoId, BitsAsInFamousoLittleEndianPcLayout) {
  // priority 7 bits at 28..22, fragment flag 21, TxNode 20..14, etag 13..0.
  EXPECT_EQ(encode_famouso_id({0x7F, false, 0, 0}), 0x1FC00000u);
  EXPECT_EQ(encode_famouso_id({0, true, 0, 0}), 0x00200000u);
  EXPECT_EQ(encode_famouso_id({0, false, 0x7F, 0}), 0x001FC000u);
  EXPECT_EQ(encode_famouso_id({0, false, 0, 0x3FFF}), 0x00003FFFu);
  // FAMOUSO's prio(0xFD): low 2 bits 01, high 5 bits 11111 -> 0x7D.
  EXPECT_EQ(encode_famouso_id({kFamousoProtocolPriority, false, 0x23, kEtagGetEtag}), 0x1F48C002u);
  const FamousoIdentifier id{0x45, true, 0x12, 777};
  EXPECT_EQ(decode_famouso_id(encode_famouso_id(id)), id);
  // TxNode and etag are where our layout has them.
  EXPECT_EQ(decode_can_id(encode_famouso_id(id)).tx_node, 0x12);
  EXPECT_EQ(decode_can_id(encode_famouso_id(id)).etag, 777);
}

TEST(FamousoId, PrioritiesKeepClassBandsAndOrder) {
  EXPECT_EQ(famouso_priority(0x00), 0x00);
  EXPECT_EQ(famouso_priority(0x0F), 0x0F);  // all 16 HRT levels
  EXPECT_EQ(famouso_priority(0x10), 0x10);
  EXPECT_EQ(famouso_priority(0x77), 0x77);  // 104 SRT levels one to one
  EXPECT_EQ(famouso_priority(0xEF), 0x77);  // beyond: the band's last level
  EXPECT_EQ(famouso_priority(0xF0), 0x78);
  EXPECT_EQ(famouso_priority(0xF7), 0x7F);
  EXPECT_EQ(famouso_priority(0xFF), 0x7F);
  for (int p = 1; p < 256; ++p) {
    EXPECT_LE(famouso_priority(static_cast<std::uint8_t>(p - 1)), famouso_priority(static_cast<std::uint8_t>(p)));
  }
  // Every HRT identifier still wins against every SRT one, and SRT against NRT and FAMOUSO's 0x7D.
  EXPECT_LT(famouso_id_of(encode_can_id({0x0F, 127, 16383}), true), famouso_id_of(encode_can_id({0x10, 0, 0}), false));
  EXPECT_LT(famouso_id_of(encode_can_id({0xEF, 127, 16383}), true), encode_famouso_id({0x78, false, 0, 0}));
  // The odd priority that sets our bit 21 does not become a fragment flag.
  EXPECT_FALSE(decode_famouso_id(famouso_id_of(encode_can_id({0x11, 1, 300}), false)).fragment);
}

TEST(FamousoBinding, AnswersOnEtag4AsFamousosBroker) {
  const FamousoIdentifier id = decode_famouso_id(can_binding::supply_etag_new_bp_id());
  EXPECT_EQ(id, (FamousoIdentifier{0x7D, false, 0x7F, 4}));
  // FAMOUSO's client: frame with byte 1 == round compares bytes 4..7 with subject half `round`,
  // and takes the etag from frame 1 (bytes 2, 3), whatever byte 0 says.
  const auto frames = can_binding::supply_etag_data(0x23, 0x3FFF, kFamousoSubscribeSubject);
  const auto subject = can_binding::get_etag_data(kFamousoSubscribeSubject);
  for (std::uint8_t round = 0; round < 2; ++round) {
    EXPECT_EQ(frames[round][1], round);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(frames[round][4 + i], subject[4 * round + i]);
  }
  EXPECT_EQ(((frames[1][2] & 0x3F) << 8) + frames[1][3], 0x3FFF);
  EXPECT_EQ(std::string(subject.begin(), subject.end()), "SUBSCRIB");  // FAMOUSO's Subject("SUBSCRIBE")
}

TEST(FamousoAfp, HeadersAsAfpWritesThem) {
  std::array<std::uint8_t, 8> b{};
  EXPECT_EQ(famouso::encode_afp_header(2, true, b), 1u);
  EXPECT_EQ(b[0], 0x22);  // 0 | ext 0 | first 1 | fseq 00010
  b = {};
  EXPECT_EQ(famouso::encode_afp_header(0, false, b), 1u);
  EXPECT_EQ(b[0], 0x00);
  b = {};
  EXPECT_EQ(famouso::encode_afp_header(31, false, b), 1u);
  EXPECT_EQ(b[0], 0x1F);
  b = {};
  EXPECT_EQ(famouso::encode_afp_header(32, true, b), 2u);  // 10 | ext 0 | first 1 | 12-bit fseq
  EXPECT_EQ(b[0], 0x90);
  EXPECT_EQ(b[1], 0x20);
  b = {};
  EXPECT_EQ(famouso::encode_afp_header(4095, false, b), 2u);
  EXPECT_EQ(b[0], 0x8F);
  EXPECT_EQ(b[1], 0xFF);
  for (std::uint32_t r : {0u, 5u, 31u, 32u, 100u, 4095u, 4096u, 70000u}) {
    for (bool first : {false, true}) {
      std::array<std::uint8_t, 8> h{};
      const std::size_t len = famouso::encode_afp_header(r, first, h);
      const auto d = famouso::decode_afp_header(h);
      ASSERT_TRUE(d.has_value()) << r;
      EXPECT_EQ(d->remaining, r);
      EXPECT_EQ(d->first, first);
      EXPECT_EQ(d->length, len);
    }
  }
  const std::array<std::uint8_t, 2> extension{0x40, 0x00};  // event sequence header: not on CAN
  EXPECT_FALSE(famouso::decode_afp_header(extension).has_value());
  const std::array<std::uint8_t, 1> header_only{0x90};  // a 2-byte header cut short
  EXPECT_FALSE(famouso::decode_afp_header(header_only).has_value());
}

std::vector<std::uint8_t> counting(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  std::iota(v.begin(), v.end(), std::uint8_t{1});
  return v;
}

std::vector<std::vector<std::uint8_t>> fragment(const std::vector<std::uint8_t>& event) {
  std::vector<std::vector<std::uint8_t>> out;
  AfpFragmenter f(event);
  while (!f.done()) {
    std::array<std::uint8_t, 8> buf{};
    out.emplace_back(buf.begin(), buf.begin() + f.next(buf));
  }
  return out;
}

TEST(FamousoAfp, FragmentsAsFamousoCutsThem) {
  // 16 bytes: 3 fragments of 7 + 7 + 2 event bytes, sequence numbers 2, 1, 0.
  const auto frames = fragment(counting(16));
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0], (std::vector<std::uint8_t>{0x22, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(frames[1], (std::vector<std::uint8_t>{0x01, 8, 9, 10, 11, 12, 13, 14}));
  EXPECT_EQ(frames[2], (std::vector<std::uint8_t>{0x00, 15, 16}));
  EXPECT_EQ(famouso::afp_fragment_count(9), 2u);
  EXPECT_EQ(famouso::afp_fragment_count(224), 32u);  // 32 fragments of 7
  EXPECT_EQ(famouso::afp_fragment_count(225), 33u);  // one more with a 2-byte header, 6 bytes
  EXPECT_EQ(famouso::afp_fragment_count(230), 33u);
  EXPECT_EQ(famouso::afp_fragment_count(231), 34u);
  const auto big = fragment(counting(1000));
  EXPECT_EQ(big.size(), famouso::afp_fragment_count(1000));
  EXPECT_EQ(big.front()[0] & 0xF0, 0x90);  // 2-byte header, first
  for (const auto& f : big) EXPECT_LE(f.size(), 8u);
}

TEST(FamousoAfp, ReassemblesWhatItFragments) {
  AfpReassembler r;
  for (std::size_t n : {9u, 16u, 224u, 225u, 1000u, 12288u}) {
    const auto event = counting(n);
    std::vector<std::uint8_t> got;
    for (const auto& f : fragment(event)) {
      const auto res = r.accept(7, f, 12288, Nanos(0));
      ASSERT_NE(res.outcome, AfpOutcome::rejected) << n;
      if (res.outcome == AfpOutcome::complete) got.assign(res.event.begin(), res.event.end());
    }
    EXPECT_EQ(got, event) << n;
  }
}

TEST(FamousoAfp, LossesAndBoundsDropTheEvent) {
  AfpReassembler r;
  auto frames = fragment(counting(30));  // 5 fragments
  EXPECT_EQ(r.accept(1, frames[0], 100, Nanos(0)).outcome, AfpOutcome::partial);
  auto gap = r.accept(1, frames[2], 100, Nanos(0));  // fragment 1 lost
  EXPECT_EQ(gap.outcome, AfpOutcome::rejected);
  EXPECT_TRUE(gap.dropped_event);
  EXPECT_EQ(r.accept(1, frames[3], 100, Nanos(0)).outcome, AfpOutcome::rejected);  // rest discarded
  // A new first fragment replaces a partial event, counted.
  EXPECT_EQ(r.accept(2, frames[0], 100, Nanos(0)).outcome, AfpOutcome::partial);
  EXPECT_TRUE(r.accept(2, frames[0], 100, Nanos(0)).dropped_event);
  // Larger than the channel's payload.
  AfpReassembler small;
  std::size_t rejected = 0;
  for (const auto& f : frames) rejected += small.accept(3, f, 20, Nanos(0)).outcome == AfpOutcome::rejected;
  EXPECT_GE(rejected, 1u);
  // Idle partial events expire.
  AfpReassembler timed(famouso::AfpLimits{2, Nanos(1000)});
  timed.accept(4, frames[0], 100, Nanos(0));
  std::vector<std::uint32_t> expired;
  timed.expire(Nanos(500), [&](std::uint32_t s) { expired.push_back(s); });
  EXPECT_TRUE(expired.empty());
  timed.expire(Nanos(1001), [&](std::uint32_t s) { expired.push_back(s); });
  EXPECT_EQ(expired, std::vector<std::uint32_t>{4});
  // Only max_partial_events at once: the one idle longest makes room.
  timed.accept(5, frames[0], 100, Nanos(10));
  timed.accept(6, frames[0], 100, Nanos(20));
  EXPECT_EQ(timed.accept(8, frames[0], 100, Nanos(30)).displaced, std::optional<std::uint32_t>(5));
}

// A node following FAMOUSO's ccp/Client.h: one nibble per stage, waits for answers.
struct CcpNode {
  explicit CcpNode(std::array<std::uint8_t, 8> u) : uid(u) {}
  std::array<std::uint8_t, 8> uid;
  int stage = famouso::kCcpFirstStage;
  std::optional<std::uint8_t> tx_node;

  std::uint8_t nibble() const {
    const std::uint8_t byte = uid[(15 - stage) >> 1];
    return stage % 2 ? byte >> 4 : byte & 0xF;
  }
  std::uint32_t request() const { return famouso::encode_ccp_request(static_cast<std::uint8_t>(stage), nibble()); }
  bool matches(const std::array<std::uint8_t, 8>& data, int down_to) const {
    for (int s = 15; s >= down_to; --s) {
      const int part = (15 - s) >> 1;
      const int a = s % 2 ? uid[part] >> 4 : uid[part] & 0xF;
      const int b = s % 2 ? data[part] >> 4 : data[part] & 0xF;
      if (a != b) return false;
    }
    return true;
  }
  // Returns true when the node sends its next request.
  bool on_answer(const famouso::CcpFrame& f) {
    if (tx_node) return false;
    const FamousoIdentifier id = decode_famouso_id(f.can_id);
    if (id.etag != kEtagCcpSsi) return false;
    if (id.tx_node == kFamousoBrokerNode) {
      const std::array<std::uint8_t, 8> zeros{};
      if (f.data == zeros) {
        stage = famouso::kCcpFirstStage;
        return true;
      }
      if (stage == (f.data[7] & 0xF) && matches(f.data, stage)) {
        --stage;
        return true;
      }
      return false;
    }
    if (matches(f.data, 0)) {
      tx_node = id.tx_node;
    } else {
      stage = famouso::kCcpFirstStage;
      return true;
    }
    return false;
  }
};

TEST(FamousoCcp, AssignsTxNodesToNodesThatStartTogether) {
  famouso::CcpBroker broker;
  broker.reserve(1);
  std::vector<CcpNode> nodes{CcpNode({'S', 'c', 'h', 'u', 'l', 'z', 'e', 0}),
                             CcpNode({'S', 'c', 'h', 'u', 'l', 'z', 'e', 1}),
                             CcpNode({'N', 'o', 'd', 'e', '-', 'B', 0, 0})};
  // The bus: every node with a pending request sends; arbitration lets the lowest identifier
  // through first, the broker sees all of them in that order, every node sees every answer.
  std::vector<bool> pending(nodes.size(), true);
  for (int step = 0; step < 500; ++step) {
    std::vector<std::pair<std::uint32_t, std::size_t>> sending;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (pending[i]) sending.emplace_back(nodes[i].request(), i);
    }
    if (sending.empty()) break;
    std::sort(sending.begin(), sending.end());
    for (auto& [id, i] : sending) {
      pending[i] = false;
      if (const auto answer = broker.on_request(id, Nanos(step))) {
        for (std::size_t n = 0; n < nodes.size(); ++n) pending[n] = nodes[n].on_answer(*answer) || pending[n];
      }
    }
  }
  std::set<int> given;
  for (const auto& n : nodes) {
    ASSERT_TRUE(n.tx_node.has_value());
    EXPECT_NE(*n.tx_node, 1);     // the gateway's own
    EXPECT_LT(*n.tx_node, 0x7F);  // not the broker's
    given.insert(*n.tx_node);
  }
  EXPECT_EQ(given.size(), nodes.size());
  EXPECT_EQ(*given.rbegin(), 0x7E);  // highest free first, as FAMOUSO's broker
}

TEST(FamousoCcp, RestartedNodeGetsItsTxNodeAgainAndStuckRoundsExpire) {
  famouso::CcpBroker broker(Nanos(100));
  CcpNode node({1, 2, 3, 4, 5, 6, 7, 8});
  auto run = [&](CcpNode& n) {
    for (int i = 0; i < 20 && !n.tx_node; ++i) {
      const auto a = broker.on_request(n.request(), Nanos(0));
      ASSERT_TRUE(a.has_value());
      n.on_answer(*a);
    }
  };
  run(node);
  ASSERT_TRUE(node.tx_node.has_value());
  CcpNode again(node.uid);
  run(again);
  EXPECT_EQ(again.tx_node, node.tx_node);
  // A node that stops after stage 15 holds the broker in stage 14 ...
  EXPECT_TRUE(broker.on_request(famouso::encode_ccp_request(15, 3), Nanos(1000)).has_value());
  EXPECT_FALSE(broker.on_request(famouso::encode_ccp_request(15, 3), Nanos(1001)).has_value());
  EXPECT_EQ(broker.deadline(), std::optional<Nanos>(Nanos(1100)));
  EXPECT_FALSE(broker.expire(Nanos(1099)).has_value());
  // ... until the round times out: an all-zero answer makes waiting nodes start over.
  const auto reset = broker.expire(Nanos(1100));
  ASSERT_TRUE(reset.has_value());
  EXPECT_EQ(reset->data, (std::array<std::uint8_t, 8>{}));
  EXPECT_EQ(decode_famouso_id(reset->can_id).tx_node, kFamousoBrokerNode);
  EXPECT_TRUE(broker.on_request(famouso::encode_ccp_request(15, 3), Nanos(1200)).has_value());
}

TEST(BindingGuard, RateLimitPerNodeAndPerBus) {
  BindingRateLimit limit(10, 100);
  int admitted = 0;
  for (int i = 0; i < 50; ++i) admitted += limit.admit(5, Nanos(0));
  EXPECT_EQ(admitted, 4);                 // burst of one node
  EXPECT_TRUE(limit.admit(6, Nanos(0)));  // another node has its own budget
  EXPECT_FALSE(limit.admit(5, Nanos(50'000'000)));
  EXPECT_TRUE(limit.admit(5, Nanos(100'000'000)));  // 10/s: one more after 100 ms
  BindingRateLimit bus(1000, 100);
  admitted = 0;
  for (int n = 0; n < 100; ++n) admitted += bus.admit(static_cast<std::uint8_t>(n), Nanos(0));
  EXPECT_EQ(admitted, 32);  // bus-wide burst
}

TEST(BindingGuard, AnswersLeaveOneAtATimePaced) {
  ProtocolQueue q(Nanos(1000), 3);
  can_frame f{};
  EXPECT_EQ(q.due(Nanos(0)), nullptr);
  ASSERT_TRUE(q.room_for(2));
  f.can_id = 1;
  q.push(f);
  f.can_id = 2;
  q.push(f);
  EXPECT_FALSE(q.room_for(2));
  ASSERT_NE(q.due(Nanos(0)), nullptr);
  EXPECT_EQ(q.due(Nanos(0))->can_id, 1u);
  q.sent(Nanos(0));
  EXPECT_EQ(q.due(Nanos(999)), nullptr);  // the first is still on its way
  EXPECT_EQ(q.deadline(), std::optional<Nanos>(Nanos(1000)));
  ASSERT_NE(q.due(Nanos(1000)), nullptr);
  EXPECT_EQ(q.due(Nanos(1000))->can_id, 2u);
}

}  // namespace
}  // namespace cosmic
