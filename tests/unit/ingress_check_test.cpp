// ingress_check: every header field of an inbound event is validated against its channel before
// the router uses it; each refusal maps to a counted drop reason.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "cosmic/ingress_check.hpp"

namespace cosmic {
namespace {

constexpr std::uint64_t kSelf = 0x5E1F;
constexpr std::uint64_t kSubject = 0x0000000100000042;

class IngressCheckTest : public ::testing::Test {
 protected:
  IngressCheckTest() {
    spec.name = "distance";
    spec.subject = kSubject;
    spec.payload = 4;
    event.channel = 7;
    event.header.subject = kSubject;
    event.header.origin = 0x0717;
    event.header.sequence = 12;
    event.header.hop_count = 1;
    event.header.age_ns = 250'000;
    event.payload = bytes;
  }

  IngressFault check() const { return ingress_check(event, spec, self); }

  ChannelSpec spec;
  GatewayIdentity self{kSelf, "test"};
  std::vector<std::uint8_t> bytes{1, 2, 3, 4};
  InboundEvent event;
};

TEST_F(IngressCheckTest, AWellFormedEventPasses) { EXPECT_EQ(check(), IngressFault::none); }

TEST_F(IngressCheckTest, ANativeEventWithOriginZeroPasses) {
  event.header.origin = 0;
  event.header.sequence = 0;
  event.header.hop_count = 0;
  event.header.age_ns = 0;
  EXPECT_EQ(check(), IngressFault::none);
}

TEST_F(IngressCheckTest, NegativeAgesAreInvalid) {
  for (const std::int64_t age : {std::int64_t{-1}, std::numeric_limits<std::int64_t>::min()}) {
    event.header.age_ns = age;
    EXPECT_EQ(check(), IngressFault::negative_age) << age;
  }
  EXPECT_EQ(drop_reason(IngressFault::negative_age), DropReason::invalid);
}

TEST_F(IngressCheckTest, AgesBeyondTheBoundAreInvalidAndTheBoundItselfPasses) {
  event.header.age_ns = kMaxIngressAgeNs;
  EXPECT_EQ(check(), IngressFault::none);
  for (const std::int64_t age : {kMaxIngressAgeNs + 1, std::numeric_limits<std::int64_t>::max()}) {
    event.header.age_ns = age;
    EXPECT_EQ(check(), IngressFault::age_beyond_bound) << age;
  }
  EXPECT_EQ(drop_reason(IngressFault::age_beyond_bound), DropReason::invalid);
}

TEST_F(IngressCheckTest, TheBoundLeavesRoomForResidenceWithoutOverflow) {
  // The router adds residence time (and subtracts from the wall clock): a century of either
  // must not overflow on top of the largest accepted age.
  constexpr std::int64_t kCentury = 100LL * 365 * 24 * 3600 * 1'000'000'000LL;
  EXPECT_LT(kMaxIngressAgeNs, std::numeric_limits<std::int64_t>::max() - kCentury);
}

TEST_F(IngressCheckTest, ASubjectThatIsNotTheChannelsIsInvalid) {
  event.header.subject = kSubject + 1;
  EXPECT_EQ(check(), IngressFault::foreign_subject);
  event.header.subject = 0;
  EXPECT_EQ(check(), IngressFault::foreign_subject);
  EXPECT_EQ(drop_reason(IngressFault::foreign_subject), DropReason::invalid);
}

TEST_F(IngressCheckTest, OurOwnOriginComingBackIsALoopCopy) {
  event.header.origin = kSelf;
  EXPECT_EQ(check(), IngressFault::own_origin);
  EXPECT_EQ(drop_reason(IngressFault::own_origin), DropReason::duplicate);
}

TEST_F(IngressCheckTest, HopCountAtTheLimitIsALoopAndBelowItPasses) {
  event.header.hop_count = kMaxHops - 1;
  EXPECT_EQ(check(), IngressFault::none);
  event.header.hop_count = kMaxHops;
  EXPECT_EQ(check(), IngressFault::hop_limit);
  event.header.hop_count = 0xFF;
  EXPECT_EQ(check(), IngressFault::hop_limit);
  EXPECT_EQ(drop_reason(IngressFault::hop_limit), DropReason::duplicate);
}

TEST_F(IngressCheckTest, PayloadLargerThanTheAdmittedContractIsOversize) {
  bytes.push_back(5);
  event.payload = bytes;
  EXPECT_EQ(check(), IngressFault::oversize);
  EXPECT_EQ(drop_reason(IngressFault::oversize), DropReason::oversize);
  spec.payload = 5;  // exactly the contract
  EXPECT_EQ(check(), IngressFault::none);
}

TEST_F(IngressCheckTest, AnEmptyPayloadPasses) {
  event.payload = {};
  EXPECT_EQ(check(), IngressFault::none);
}

TEST_F(IngressCheckTest, EveryFaultHasAName) {
  for (const IngressFault f :
       {IngressFault::none, IngressFault::negative_age, IngressFault::age_beyond_bound, IngressFault::foreign_subject,
        IngressFault::own_origin, IngressFault::hop_limit, IngressFault::oversize}) {
    EXPECT_STRNE(to_string(f), "?");
  }
}

}  // namespace
}  // namespace cosmic
