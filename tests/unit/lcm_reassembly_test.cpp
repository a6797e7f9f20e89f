// LcmReassembler against fragments no honest LCM sender produces: what it must refuse without
// holding memory for them (cosmic/lcm_reassembly.hpp). The well-formed cases are in
// lcm_udpm_test.cpp.
#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "cosmic/lcm_reassembly.hpp"
#include "lcm_fragment_builder.hpp"

namespace cosmic {
namespace {

using Outcome = LcmReassembler::Outcome;

TEST(LcmReassemblerHostile, ALateDuplicateOfADeliveredMessageStartsNothing) {
  const std::vector<std::uint8_t> bytes(20, 0x42);
  const std::span<const std::uint8_t> whole(bytes);
  LcmReassembler reassembler(100);
  ASSERT_EQ(reassembler.add(9, make_fragment(4, 20, 0, 0, 2, whole.first(10), "c")), Outcome::pending);
  ASSERT_EQ(reassembler.add(9, make_fragment(4, 20, 10, 1, 2, whole.subspan(10))), Outcome::complete);
  // The network delivers fragment 1 twice; the second copy comes after the message was whole.
  EXPECT_EQ(reassembler.add(9, make_fragment(4, 20, 10, 1, 2, whole.subspan(10))), Outcome::ignored);
  EXPECT_EQ(reassembler.messages_held(), 0u);
  EXPECT_EQ(reassembler.bytes_held(), 0u);
  // The sender's next message is not disturbed, and nothing was counted lost.
  ASSERT_EQ(reassembler.add(9, make_fragment(5, 20, 0, 0, 2, whole.first(10), "c")), Outcome::pending);
  EXPECT_EQ(reassembler.add(9, make_fragment(5, 20, 10, 1, 2, whole.subspan(10))), Outcome::complete);
  EXPECT_EQ(reassembler.abandoned(), 0u);
}

TEST(LcmReassemblerHostile, ASkippedMessageHoldsNothingAndItsFragmentsAreIgnored) {
  const std::vector<std::uint8_t> bytes(30, 0x11);
  const std::span<const std::uint8_t> whole(bytes);
  LcmReassembler reassembler(100);
  // Fragment 1 came before fragment 0 (reordered): it is held until fragment 0 says "skip".
  ASSERT_EQ(reassembler.add(3, make_fragment(8, 30, 10, 1, 3, whole.subspan(10, 10))), Outcome::pending);
  EXPECT_EQ(reassembler.messages_held(), 1u);
  reassembler.skip(3, 8);
  EXPECT_EQ(reassembler.messages_held(), 0u);
  EXPECT_EQ(reassembler.bytes_held(), 0u);
  EXPECT_EQ(reassembler.add(3, make_fragment(8, 30, 20, 2, 3, whole.subspan(20))), Outcome::ignored);
  EXPECT_EQ(reassembler.messages_held(), 0u);
  EXPECT_EQ(reassembler.abandoned(), 0u);
  // The sender's next message is reassembled as usual.
  ASSERT_EQ(reassembler.add(3, make_fragment(9, 30, 0, 0, 3, whole.first(10), "c")), Outcome::pending);
  ASSERT_EQ(reassembler.add(3, make_fragment(9, 30, 10, 1, 3, whole.subspan(10, 10))), Outcome::pending);
  EXPECT_EQ(reassembler.add(3, make_fragment(9, 30, 20, 2, 3, whole.subspan(20))), Outcome::complete);
}

TEST(LcmReassemblerHostile, MoreFragmentsThanBytesAreRefusedAtOnce) {
  // Ten bytes cannot come in more than eleven fragments (the first may carry only the channel):
  // 65,535 of them would only make us keep a flag and a slice per fragment.
  const std::vector<std::uint8_t> one(1, 0x01);
  LcmReassembler reassembler(100);
  EXPECT_EQ(reassembler.add(1, make_fragment(1, 10, 0, 0, 65535, {}, "c")), Outcome::refused);
  EXPECT_EQ(reassembler.add(1, make_fragment(1, 10, 0, 0, 12, {}, "c")), Outcome::refused);
  EXPECT_EQ(reassembler.messages_held(), 0u);
  EXPECT_EQ(reassembler.add(1, make_fragment(2, 10, 0, 0, 11, {}, "c")), Outcome::pending);
}

TEST(LcmReassemblerHostile, AFragmentNumberBeyondTheCountIsRefusedWhoeverBuiltIt) {
  // parse_lcm_datagram never yields one; the reassembler does not rely on that.
  const std::vector<std::uint8_t> bytes(4, 0x07);
  LcmReassembler reassembler(100);
  EXPECT_EQ(reassembler.add(1, make_fragment(1, 8, 4, 2, 2, bytes)), Outcome::refused);
  EXPECT_EQ(reassembler.add(1, make_fragment(1, 8, 4, 7, 2, bytes)), Outcome::refused);
  EXPECT_EQ(reassembler.messages_held(), 0u);
}

}  // namespace
}  // namespace cosmic
