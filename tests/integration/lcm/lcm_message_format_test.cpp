// The LCM wire formats as units (lcm_message_format.hpp): what each reads from a message, what it
// writes for an event, and what it says it carries of an event's identity.
#include "lcm_message_format.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace cosmic::lcm_detail {
namespace {

std::vector<std::uint8_t> joined(const LcmMessageParts& parts, std::size_t count) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < count; ++i) out.insert(out.end(), parts[i].begin(), parts[i].end());
  return out;
}

TEST(LcmMessageFormat, TheEnvelopeCarriesTheWholeHeaderAndReadsBackWhatItWrote) {
  const auto format = make_lcm_message_format(LcmEncoding::envelope);
  EXPECT_EQ(format->encoding(), LcmEncoding::envelope);
  EXPECT_EQ(format->identity(), FormatIdentity{});
  EXPECT_FALSE(format->identity().needs_fingerprint_loop_guard());
  const std::vector<std::uint8_t> contents{9, 8, 7};
  OutboundEvent out;
  out.header = EventHeader{0x42, 0x1234, 7, 2, 1'000, 250};
  out.payload = contents;
  LcmHeaderBuffer header{};
  LcmMessageParts parts{};
  const std::size_t count = format->encode(out, header, parts);
  ASSERT_EQ(count, 2u);
  const std::vector<std::uint8_t> message = joined(parts, count);
  EXPECT_EQ(message.size(), kLcmEnvelopeHeaderSize + contents.size());
  InboundEvent in;
  ASSERT_TRUE(format->decode(message, LcmArrival{0x99, 5}, 3, in));
  EXPECT_EQ(in.header.subject, 0x42u) << "the envelope's subject, not the channel's";
  EXPECT_EQ(in.header.origin, 0x1234u);
  EXPECT_EQ(in.header.sequence, 7u);
  EXPECT_EQ(in.header.hop_count, 2u);
  EXPECT_EQ(in.header.age_ns, 250);
  EXPECT_EQ(std::vector<std::uint8_t>(in.payload.begin(), in.payload.end()), contents);
  EXPECT_FALSE(format->decode(message, LcmArrival{}, 2, in)) << "contents beyond max_message_size";
  EXPECT_FALSE(format->decode(std::span(message).first(message.size() - 1), LcmArrival{}, 3, in)) << "a byte short";
}

TEST(LcmMessageFormat, RawCarriesTheContentsAloneAndNoIdentity) {
  const auto format = make_lcm_message_format(LcmEncoding::raw);
  EXPECT_EQ(format->encoding(), LcmEncoding::raw);
  EXPECT_FALSE(format->identity().origin);
  EXPECT_FALSE(format->identity().sequence);
  EXPECT_FALSE(format->identity().hop_count);
  EXPECT_TRUE(format->identity().needs_fingerprint_loop_guard()) << "two gateways on one group hand copies back";
  const std::vector<std::uint8_t> contents{1, 2, 3, 4};
  OutboundEvent out;
  out.header = EventHeader{0x42, 0x1234, 7, 2, 1'000, 250};  // none of it travels
  out.payload = contents;
  LcmHeaderBuffer header{};
  LcmMessageParts parts{};
  const std::size_t count = format->encode(out, header, parts);
  ASSERT_EQ(count, 1u);
  EXPECT_EQ(joined(parts, count), contents);
  InboundEvent in;
  ASSERT_TRUE(format->decode(contents, LcmArrival{0x99, 5'000}, 4, in));
  EXPECT_EQ(in.header.subject, 0x99u) << "the channel's subject";
  EXPECT_EQ(in.header.origin, 0u);
  EXPECT_EQ(in.header.created_ns, 5'000) << "the arrival time stands in for the creation time";
  EXPECT_EQ(in.payload.data(), contents.data()) << "a view, no copy";
  EXPECT_TRUE(in.identity.needs_fingerprint_loop_guard());
  EXPECT_FALSE(format->decode(contents, LcmArrival{}, 3, in)) << "contents beyond max_message_size";
}

}  // namespace
}  // namespace cosmic::lcm_detail
