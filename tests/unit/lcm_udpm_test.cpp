// LCM's UDP multicast datagrams (cosmic/lcm_udpm.hpp) and the reassembly of fragmented messages
// (cosmic/lcm_reassembly.hpp): the header bytes, what parse_lcm_datagram refuses, how
// plan_lcm_message splits a message (as liblcm does), fragments through LcmReassembler in and out
// of order, and its bounds (duplicates, inconsistent fragments, sender slots, byte budget,
// overlapping slices).
#include "cosmic/lcm_udpm.hpp"
#include "cosmic/lcm_reassembly.hpp"
#include "lcm_fragment_builder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cosmic {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Outcome = LcmReassembler::Outcome;

constexpr std::uint32_t kU32Max = std::numeric_limits<std::uint32_t>::max();

Bytes pattern(std::size_t n, std::uint8_t seed = 0) {
  Bytes v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(seed + i * 7 + (i >> 8));
  return v;
}

void append(Bytes& out, std::string_view s) { out.insert(out.end(), s.begin(), s.end()); }
void append(Bytes& out, std::span<const std::uint8_t> s) { out.insert(out.end(), s.begin(), s.end()); }

bool same(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) { return std::ranges::equal(a, b); }

// A short message as liblcm sends it: header, channel, NUL, payload.
Bytes short_datagram(std::uint32_t sequence, std::string_view channel, std::span<const std::uint8_t> payload) {
  Bytes out;
  append(out, lcm_short_header(sequence));
  append(out, channel);
  out.push_back(0);
  append(out, payload);
  return out;
}

// One fragment: header, then (fragment 0 only) channel and NUL, then the slice.
Bytes fragment_datagram(std::uint32_t sequence, std::uint32_t message_size, std::uint32_t offset, std::uint16_t no,
                        std::uint16_t count, std::string_view channel, std::span<const std::uint8_t> slice) {
  Bytes out;
  append(out, lcm_fragment_header(sequence, message_size, offset, no, count));
  if (no == 0) {
    append(out, channel);
    out.push_back(0);
  }
  append(out, slice);
  return out;
}

// The datagrams of a fragmented message exactly as a sender following plan_lcm_message sends
// them: fragment 0 carries channel, NUL and first_slice payload bytes, each later one up to
// kLcmFragmentMaxData bytes at its offset into the payload.
std::vector<Bytes> send_fragmented(std::uint32_t sequence, std::string_view channel, const Bytes& payload) {
  std::vector<Bytes> out;
  const auto plan = plan_lcm_message(channel.size(), payload.size());
  if (!plan || plan->fragment_count == 0) {
    ADD_FAILURE() << "a payload of " << payload.size() << " bytes is not planned as fragments";
    return out;
  }
  const auto size = static_cast<std::uint32_t>(payload.size());
  std::size_t offset = 0;
  for (std::uint16_t no = 0; no < plan->fragment_count; ++no) {
    const std::size_t left = payload.size() - std::min(offset, payload.size());
    const std::size_t n = std::min(no == 0 ? plan->first_slice : kLcmFragmentMaxData, left);
    out.push_back(fragment_datagram(sequence, size, static_cast<std::uint32_t>(offset), no, plan->fragment_count,
                                    channel, std::span(payload).subspan(offset, n)));
    EXPECT_LE(out.back().size(), kLcmMaxDatagram) << "fragment " << no;
    offset += n;
  }
  EXPECT_EQ(offset, payload.size()) << "the plan's fragments do not carry the whole payload";
  return out;
}

// Spans of the result point into `datagrams`, which must outlive it.
std::vector<LcmDatagram> parse_all(const std::vector<Bytes>& datagrams) {
  std::vector<LcmDatagram> out;
  for (std::size_t i = 0; i < datagrams.size(); ++i) {
    const auto parsed = parse_lcm_datagram(datagrams[i]);
    if (!parsed) {
      ADD_FAILURE() << "datagram " << i << " does not parse";
      continue;
    }
    out.push_back(*parsed);
  }
  return out;
}

bool parses(const Bytes& datagram) { return parse_lcm_datagram(datagram).has_value(); }

Bytes then(std::span<const std::uint8_t> header, std::string_view text) {
  Bytes out(header.begin(), header.end());
  append(out, text);
  return out;
}

TEST(LcmUdpmHeader, ShortHeaderIsLc02MagicThenSequenceBigEndian) {
  const std::array<std::uint8_t, kLcmShortHeaderSize> expected{0x4c, 0x43, 0x30, 0x32, 0x01, 0x02, 0x03, 0x04};
  EXPECT_EQ(lcm_short_header(0x01020304), expected);
  const std::array<std::uint8_t, kLcmShortHeaderSize> max{0x4c, 0x43, 0x30, 0x32, 0xff, 0xff, 0xff, 0xff};
  EXPECT_EQ(lcm_short_header(kU32Max), max);
}

TEST(LcmUdpmHeader, FragmentHeaderIsLc03MagicSequenceSizeOffsetNumberCountBigEndian) {
  // "LC03", sequence, message size, fragment offset, fragment number, fragment count.
  const std::array<std::uint8_t, kLcmFragmentHeaderSize> expected{0x4c, 0x43, 0x30, 0x33, 0x01, 0x02, 0x03,
                                                                  0x04, 0x0a, 0x0b, 0x0c, 0x0d, 0x11, 0x12,
                                                                  0x13, 0x14, 0x21, 0x22, 0x31, 0x32};
  EXPECT_EQ(lcm_fragment_header(0x01020304, 0x0a0b0c0d, 0x11121314, 0x2122, 0x3132), expected);
}

TEST(LcmUdpmParse, ShortMessageParsesBackToSequenceChannelAndPayload) {
  const Bytes payload = pattern(200, 3);
  const Bytes datagram = short_datagram(0xdeadbeef, "POSE", payload);
  const auto parsed = parse_lcm_datagram(datagram);
  ASSERT_TRUE(parsed.has_value());
  EXPECT_FALSE(parsed->fragment);
  EXPECT_EQ(parsed->sequence, 0xdeadbeefu);
  EXPECT_EQ(parsed->channel, "POSE");
  EXPECT_TRUE(same(parsed->data, payload));
  // Views into the datagram, not copies: the adapter hands them on without copying.
  EXPECT_EQ(static_cast<const void*>(parsed->channel.data()), static_cast<const void*>(datagram.data() + 8));
  EXPECT_EQ(parsed->data.data(), datagram.data() + 8 + 5);

  const Bytes empty_datagram = short_datagram(7, "EMPTY", {});  // the views point into it
  const auto empty = parse_lcm_datagram(empty_datagram);
  ASSERT_TRUE(empty.has_value());
  EXPECT_EQ(empty->channel, "EMPTY");
  EXPECT_TRUE(empty->data.empty());
}

TEST(LcmUdpmParse, FragmentsParseBackToTheirHeaderFieldsAndSlice) {
  const Bytes first_slice = pattern(10, 1);
  const Bytes first = fragment_datagram(77, 1000, 0, 0, 3, "POSE", first_slice);
  const auto f0 = parse_lcm_datagram(first);
  ASSERT_TRUE(f0.has_value());
  EXPECT_TRUE(f0->fragment);
  EXPECT_EQ(f0->sequence, 77u);
  EXPECT_EQ(f0->message_size, 1000u);
  EXPECT_EQ(f0->fragment_offset, 0u);
  EXPECT_EQ(f0->fragment_no, 0);
  EXPECT_EQ(f0->fragment_count, 3);
  EXPECT_EQ(f0->channel, "POSE");
  EXPECT_TRUE(same(f0->data, first_slice));

  // A later fragment carries no channel: its slice starts right after the header even when its
  // first byte is a NUL (pattern(10, 0) starts with 0).
  const Bytes last_slice = pattern(10, 0);
  ASSERT_EQ(last_slice[0], 0);
  const Bytes last = fragment_datagram(77, 1000, 990, 2, 3, "", last_slice);
  const auto f2 = parse_lcm_datagram(last);
  ASSERT_TRUE(f2.has_value());
  EXPECT_EQ(f2->fragment_offset, 990u);
  EXPECT_EQ(f2->fragment_no, 2);
  EXPECT_EQ(f2->fragment_count, 3);
  EXPECT_TRUE(f2->channel.empty());
  EXPECT_TRUE(same(f2->data, last_slice));
  EXPECT_EQ(f2->data.data(), last.data() + kLcmFragmentHeaderSize);
}

TEST(LcmUdpmParse, RefusesDatagramsShorterThanTheirHeader) {
  const Bytes short_message = short_datagram(1, "C", pattern(4));
  for (std::size_t n = 0; n <= kLcmShortHeaderSize; ++n)
    EXPECT_FALSE(parses(Bytes(short_message.begin(), short_message.begin() + static_cast<std::ptrdiff_t>(n))))
        << n << " bytes";
  // A later fragment with an empty slice is exactly its header: valid at 20 bytes, not below.
  const Bytes fragment = fragment_datagram(1, 100, 100, 1, 2, "", {});
  ASSERT_EQ(fragment.size(), kLcmFragmentHeaderSize);
  EXPECT_TRUE(parses(fragment));
  for (std::size_t n = 0; n < kLcmFragmentHeaderSize; ++n)
    EXPECT_FALSE(parses(Bytes(fragment.begin(), fragment.begin() + static_cast<std::ptrdiff_t>(n)))) << n << " bytes";
}

TEST(LcmUdpmParse, RefusesUnknownMagic) {
  const Bytes valid = short_datagram(1, "CHAN", pattern(16));
  ASSERT_TRUE(parses(valid));
  const std::vector<std::pair<std::size_t, std::uint8_t>> corruptions{{3, '1'}, {3, '4'}, {0, 'l'}, {1, 'c'}, {2, '1'}};
  for (const auto& [index, value] : corruptions) {
    Bytes bad = valid;
    bad[index] = value;
    EXPECT_FALSE(parses(bad)) << "byte " << index << " = " << int{value};
  }
  EXPECT_FALSE(parses(Bytes(64, 0)));
}

TEST(LcmUdpmParse, RefusesChannelWithoutNulInItsFirst64Bytes) {
  EXPECT_FALSE(parses(then(lcm_short_header(1), std::string(100, 'a'))));
  EXPECT_FALSE(parses(then(lcm_short_header(1), "abc")));  // the datagram ends first

  // A NUL that is the 65th byte comes too late: the channel would have 64 bytes.
  EXPECT_FALSE(parses(short_datagram(1, std::string(64, 'a'), pattern(8))));
  EXPECT_FALSE(parses(short_datagram(1, std::string(100, 'a'), pattern(8))));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 0, 0, 2, std::string(64, 'a'), pattern(8))));
  EXPECT_FALSE(parses(then(lcm_fragment_header(1, 100, 0, 0, 2), std::string(80, 'a'))));
}

TEST(LcmUdpmParse, RefusesEmptyChannel) {
  EXPECT_FALSE(parses(short_datagram(1, "", pattern(8))));
  EXPECT_FALSE(parses(short_datagram(1, "", {})));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 0, 0, 2, "", pattern(8))));
}

TEST(LcmUdpmParse, AcceptsChannelOf63BytesAndRefuses64) {
  const std::string c63(kLcmMaxChannelBytes, 'c');
  const std::string c64(kLcmMaxChannelBytes + 1, 'c');
  const Bytes datagram63 = short_datagram(1, c63, pattern(8));  // the views point into it
  const auto short63 = parse_lcm_datagram(datagram63);
  ASSERT_TRUE(short63.has_value());
  EXPECT_EQ(short63->channel, c63);
  EXPECT_FALSE(parses(short_datagram(1, c64, pattern(8))));

  const Bytes fragment_datagram63 = fragment_datagram(1, 100, 0, 0, 2, c63, pattern(8));
  const auto fragment63 = parse_lcm_datagram(fragment_datagram63);
  ASSERT_TRUE(fragment63.has_value());
  EXPECT_EQ(fragment63->channel, c63);
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 0, 0, 2, c64, pattern(8))));
}

TEST(LcmUdpmParse, AcceptsDatagramOfExactlyMaxSizeAndRefusesOneByteMore) {
  // Short: 8-byte header + "a" + NUL + payload.
  const std::size_t payload = kLcmMaxDatagram - kLcmShortHeaderSize - 2;
  const Bytes largest = short_datagram(1, "a", pattern(payload));
  ASSERT_EQ(largest.size(), kLcmMaxDatagram);
  EXPECT_TRUE(parses(largest));
  EXPECT_FALSE(parses(short_datagram(1, "a", pattern(payload + 1))));

  // A later fragment of a large message: header + a full slice, then one byte more.
  EXPECT_TRUE(parses(fragment_datagram(1, 200000, 65482, 1, 4, "", pattern(kLcmFragmentMaxData))));
  EXPECT_FALSE(parses(fragment_datagram(1, 200000, 65482, 1, 4, "", pattern(kLcmFragmentMaxData + 1))));
}

TEST(LcmUdpmParse, RefusesFragmentNumberNotBelowCount) {
  const Bytes slice = pattern(4);
  EXPECT_TRUE(parses(fragment_datagram(1, 100, 0, 0, 1, "C", slice)));
  EXPECT_TRUE(parses(fragment_datagram(1, 100, 10, 4, 5, "", slice)));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 0, 0, 0, "C", slice)));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 10, 1, 1, "", slice)));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 10, 5, 5, "", slice)));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 10, 6, 5, "", slice)));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 10, 65535, 65535, "", slice)));
}

TEST(LcmUdpmParse, RefusesFirstFragmentWithNonzeroOffset) {
  // Fragment 0 is where the channel is: a sender always puts it at the payload's start.
  EXPECT_TRUE(parses(fragment_datagram(1, 100, 0, 0, 2, "C", pattern(10))));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 1, 0, 2, "C", pattern(10))));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 50, 0, 2, "C", pattern(10))));
}

TEST(LcmUdpmParse, RefusesFragmentWhoseSliceExceedsTheMessage) {
  EXPECT_TRUE(parses(fragment_datagram(1, 100, 90, 1, 2, "", pattern(10))));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 90, 1, 2, "", pattern(11))));
  EXPECT_TRUE(parses(fragment_datagram(1, 100, 100, 1, 2, "", {})));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, 101, 1, 2, "", {})));
  // Fragment 0's slice counts without its channel and NUL.
  EXPECT_TRUE(parses(fragment_datagram(1, 10, 0, 0, 2, "CHANNEL", pattern(10))));
  EXPECT_FALSE(parses(fragment_datagram(1, 10, 0, 0, 2, "CHANNEL", pattern(11))));
}

TEST(LcmUdpmParse, RefusesSliceEndPastMessageEvenWhenA32BitSumWouldWrap) {
  EXPECT_TRUE(parses(fragment_datagram(1, kU32Max, kU32Max - 2, 1, 2, "", pattern(2))));
  // offset + 3 is 2^32: wraps to 0 in 32 bits.
  EXPECT_FALSE(parses(fragment_datagram(1, kU32Max, kU32Max - 2, 1, 2, "", pattern(3))));
  // Wrapped sums 15 and 10 would pass a 32-bit check against a message of 100 bytes.
  EXPECT_FALSE(parses(fragment_datagram(1, 100, kU32Max, 1, 2, "", pattern(16))));
  EXPECT_FALSE(parses(fragment_datagram(1, 100, kU32Max - 9, 1, 2, "", pattern(20))));
}

// (fragment_count, first_slice) of plan_lcm_message, (-1, 0) when it refuses the message.
using Plan = std::pair<int, std::size_t>;
Plan plan(std::size_t channel_size, std::size_t payload_size) {
  const auto p = plan_lcm_message(channel_size, payload_size);
  return p ? Plan{p->fragment_count, p->first_slice} : Plan{-1, 0};
}

TEST(LcmUdpmPlan, ChannelNulAndPayloadOfExactlyShortMaxIsOneShortDatagram) {
  const std::size_t fits = kLcmShortMessageMax - 5;  // "POSE" + NUL + payload
  EXPECT_EQ(plan(4, fits), (Plan{0, fits}));
  // ... and the datagram it makes is the largest a receiver takes.
  const Bytes datagram = short_datagram(1, "POSE", pattern(fits));
  EXPECT_EQ(datagram.size(), kLcmMaxDatagram);
  EXPECT_TRUE(parses(datagram));
  EXPECT_EQ(plan(4, fits + 1), (Plan{2, kLcmFragmentMaxData - 5}));
  EXPECT_EQ(plan(kLcmMaxChannelBytes, kLcmShortMessageMax - 64), (Plan{0, kLcmShortMessageMax - 64}));
  EXPECT_EQ(plan(kLcmMaxChannelBytes, kLcmShortMessageMax - 63), (Plan{2, kLcmFragmentMaxData - 64}));
}

TEST(LcmUdpmPlan, SeventyThousandBytesOnPoseAreTwoFragmentsAsLiblcmSendsThem) {
  // liblcm: fragment 0 carries 65,487 bytes after its header, "POSE\0" taking 5 of them.
  EXPECT_EQ(plan(4, 70000), (Plan{2, 65482}));
  EXPECT_EQ(kLcmFragmentHeaderSize + 5 + 65482, kLcmMaxDatagram);
}

TEST(LcmUdpmPlan, RefusesEmptyOrOverlongChannel) {
  EXPECT_EQ(plan(0, 10), (Plan{-1, 0}));
  EXPECT_EQ(plan(0, 70000), (Plan{-1, 0}));
  EXPECT_EQ(plan(kLcmMaxChannelBytes + 1, 10), (Plan{-1, 0}));
  EXPECT_EQ(plan(kLcmMaxChannelBytes + 1, 70000), (Plan{-1, 0}));
  EXPECT_EQ(plan(1, 0), (Plan{0, 0}));
  EXPECT_EQ(plan(kLcmMaxChannelBytes, 0), (Plan{0, 0}));
}

TEST(LcmUdpmPlan, RefusesMessagesNeedingMoreThan65535Fragments) {
  // "POSE" + NUL + payload filling exactly 65,535 fragments is the largest message there is.
  const std::size_t largest = kLcmFragmentMaxData * 65535 - 5;
  EXPECT_EQ(plan(4, largest), (Plan{65535, kLcmFragmentMaxData - 5}));
  EXPECT_EQ(plan(4, largest + 1), (Plan{-1, 0}));
  EXPECT_EQ(plan(4, kLcmFragmentMaxData * 65536), (Plan{-1, 0}));
  if constexpr (sizeof(std::size_t) > sizeof(std::uint32_t)) {
    EXPECT_EQ(plan(4, std::size_t{kU32Max} + 1), (Plan{-1, 0}));
  }
}

// Feeds fragments[order[i]] in turn: pending until the last, then complete with the original.
void expect_reassembles(const std::vector<LcmDatagram>& fragments, const std::vector<std::size_t>& order,
                        std::string_view channel, const Bytes& payload) {
  LcmReassembler reassembler(1 << 20);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const Outcome outcome = reassembler.add(42, fragments[order[i]]);
    if (i + 1 < order.size()) {
      EXPECT_EQ(outcome, Outcome::pending) << "fragment " << order[i] << " at position " << i;
      EXPECT_EQ(reassembler.messages_held(), 1u);
      EXPECT_EQ(reassembler.bytes_held(), payload.size());
      continue;
    }
    ASSERT_EQ(outcome, Outcome::complete) << "fragment " << order[i] << " came last";
    EXPECT_EQ(reassembler.channel(), channel);
    EXPECT_TRUE(same(reassembler.payload(), payload));
  }
  EXPECT_EQ(reassembler.bytes_held(), 0u);
  EXPECT_EQ(reassembler.messages_held(), 0u);
  EXPECT_EQ(reassembler.abandoned(), 0u);
}

// Fisher-Yates on mt19937's raw output, which the standard fixes (std::shuffle's use of it is
// left to the library): the same order on every platform.
std::vector<std::size_t> shuffled(std::size_t n, std::uint32_t seed) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::mt19937 rng(seed);
  for (std::size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng() % i]);
  return order;
}

TEST(LcmUdpmRoundTrip, FragmentedMessageReassemblesInOrder) {
  const Bytes payload = pattern(200000, 11);
  const std::vector<Bytes> datagrams = send_fragmented(9, "POSE", payload);
  ASSERT_EQ(datagrams.size(), 4u);  // 65,482 + 65,487 + 65,487 + 3,544
  const std::vector<LcmDatagram> fragments = parse_all(datagrams);
  ASSERT_EQ(fragments.size(), datagrams.size());
  for (std::size_t i = 0; i < fragments.size(); ++i) {
    EXPECT_TRUE(fragments[i].fragment);
    EXPECT_EQ(std::size_t{fragments[i].fragment_no}, i);
    EXPECT_EQ(fragments[i].fragment_count, 4);
    EXPECT_EQ(fragments[i].message_size, 200000u);
  }
  EXPECT_EQ(fragments[0].channel, "POSE");
  EXPECT_EQ(fragments[0].data.size(), 65482u);
  EXPECT_EQ(fragments[3].data.size(), 3544u);
  expect_reassembles(fragments, {0, 1, 2, 3}, "POSE", payload);
}

TEST(LcmUdpmRoundTrip, FragmentedMessageReassemblesInAnyOrder) {
  const Bytes payload = pattern(200000, 29);
  const std::vector<Bytes> datagrams = send_fragmented(0xfffffffe, "SCAN", payload);
  const std::vector<LcmDatagram> fragments = parse_all(datagrams);
  ASSERT_EQ(fragments.size(), 4u);
  {
    SCOPED_TRACE("reversed");
    expect_reassembles(fragments, {3, 2, 1, 0}, "SCAN", payload);
  }
  bool channel_came_late = false;  // the shuffles must include fragment 0 arriving after others
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    const std::vector<std::size_t> order = shuffled(fragments.size(), seed);
    channel_came_late = channel_came_late || order.front() != 0;
    expect_reassembles(fragments, order, "SCAN", payload);
  }
  EXPECT_TRUE(channel_came_late);
}

TEST(LcmReassembler, RefusesDuplicateFragmentAndStillCompletesFromTheFirstCopies) {
  const Bytes payload = pattern(150000, 5);
  const std::vector<Bytes> datagrams = send_fragmented(3, "DUP", payload);
  const std::vector<LcmDatagram> fragments = parse_all(datagrams);
  ASSERT_EQ(fragments.size(), 3u);
  // A copy of fragment 1 with other bytes: a duplicate must not overwrite what came first.
  Bytes altered_datagram = datagrams[1];
  for (std::size_t i = kLcmFragmentHeaderSize; i < altered_datagram.size(); ++i) altered_datagram[i] ^= 0xff;
  const auto altered = parse_lcm_datagram(altered_datagram);
  ASSERT_TRUE(altered.has_value());

  LcmReassembler reassembler(1 << 20);
  EXPECT_EQ(reassembler.add(8, fragments[0]), Outcome::pending);
  EXPECT_EQ(reassembler.add(8, fragments[0]), Outcome::refused);
  EXPECT_EQ(reassembler.add(8, fragments[1]), Outcome::pending);
  EXPECT_EQ(reassembler.add(8, fragments[1]), Outcome::refused);
  EXPECT_EQ(reassembler.add(8, *altered), Outcome::refused);
  EXPECT_EQ(reassembler.add(8, fragments[0]), Outcome::refused);
  EXPECT_EQ(reassembler.messages_held(), 1u);
  EXPECT_EQ(reassembler.bytes_held(), payload.size());
  EXPECT_EQ(reassembler.abandoned(), 0u);
  ASSERT_EQ(reassembler.add(8, fragments[2]), Outcome::complete);
  EXPECT_EQ(reassembler.channel(), "DUP");
  EXPECT_TRUE(same(reassembler.payload(), payload));
  EXPECT_EQ(reassembler.bytes_held(), 0u);
}

TEST(LcmReassembler, RefusesFragmentsDisagreeingOnSizeOrCountWithoutDisturbingTheMessage) {
  const Bytes payload = pattern(10, 2);
  const std::span<const std::uint8_t> whole(payload);
  LcmReassembler reassembler(100);
  ASSERT_EQ(reassembler.add(1, make_fragment(3, 10, 0, 0, 2, whole.first(6), "c")), Outcome::pending);
  EXPECT_EQ(reassembler.add(1, make_fragment(3, 11, 6, 1, 2, whole.subspan(6))), Outcome::refused);  // size
  EXPECT_EQ(reassembler.add(1, make_fragment(3, 10, 6, 1, 3, whole.subspan(6))), Outcome::refused);  // count
  EXPECT_EQ(reassembler.add(1, make_fragment(3, 10, 6, 2, 3, whole.subspan(6))), Outcome::refused);  // count
  EXPECT_EQ(reassembler.messages_held(), 1u);
  EXPECT_EQ(reassembler.bytes_held(), 10u);
  EXPECT_EQ(reassembler.abandoned(), 0u);
  ASSERT_EQ(reassembler.add(1, make_fragment(3, 10, 6, 1, 2, whole.subspan(6))), Outcome::complete);
  EXPECT_EQ(reassembler.channel(), "c");
  EXPECT_TRUE(same(reassembler.payload(), payload));
}

TEST(LcmReassembler, RefusesShortMessagesAndMessagesLargerThanItsLimit) {
  const Bytes slice = pattern(10);
  LcmReassembler reassembler(1000);
  const Bytes short_message = short_datagram(1, "C", slice);
  const auto parsed = parse_lcm_datagram(short_message);
  ASSERT_TRUE(parsed.has_value());
  EXPECT_EQ(reassembler.add(1, *parsed), Outcome::refused);  // the adapter delivers those itself
  EXPECT_EQ(reassembler.add(1, make_fragment(1, 1001, 0, 0, 2, slice, "big")), Outcome::refused);
  EXPECT_EQ(reassembler.add(1, make_fragment(1, 1001, 500, 1, 2, slice)), Outcome::refused);
  EXPECT_EQ(reassembler.add(2, make_fragment(1, kU32Max, 0, 0, 2, slice, "huge")), Outcome::refused);
  EXPECT_EQ(reassembler.messages_held(), 0u);
  EXPECT_EQ(reassembler.bytes_held(), 0u);
  // The limit itself is allowed.
  EXPECT_EQ(reassembler.add(3, make_fragment(1, 1000, 0, 0, 2, slice, "ok")), Outcome::pending);
  EXPECT_EQ(reassembler.bytes_held(), 1000u);
}

TEST(LcmReassembler, NewSequenceFromTheSameSenderAbandonsTheUnfinishedMessage) {
  const Bytes slice = pattern(100);
  const std::span<const std::uint8_t> s(slice);
  LcmReassembler reassembler(1 << 20);
  ASSERT_EQ(reassembler.add(9, make_fragment(1, 3000, 0, 0, 2, s, "a")), Outcome::pending);
  EXPECT_EQ(reassembler.bytes_held(), 3000u);
  // liblcm sends a message's fragments back to back: sequence 2 means 1 will not be finished.
  ASSERT_EQ(reassembler.add(9, make_fragment(2, 20, 0, 0, 2, s.first(10), "b")), Outcome::pending);
  EXPECT_EQ(reassembler.abandoned(), 1u);
  EXPECT_EQ(reassembler.messages_held(), 1u);
  EXPECT_EQ(reassembler.bytes_held(), 20u);
  ASSERT_EQ(reassembler.add(9, make_fragment(2, 20, 10, 1, 2, s.subspan(10, 10))), Outcome::complete);
  EXPECT_EQ(reassembler.channel(), "b");
  EXPECT_TRUE(same(reassembler.payload(), s.first(20)));
  EXPECT_EQ(reassembler.bytes_held(), 0u);
  EXPECT_EQ(reassembler.abandoned(), 1u);
}

TEST(LcmReassembler, InterleavedSendersWithTheSameSequenceBothComplete) {
  const Bytes left = pattern(140000, 1);
  const Bytes right = pattern(140000, 2);
  const std::vector<Bytes> left_datagrams = send_fragmented(5, "LEFT", left);
  const std::vector<Bytes> right_datagrams = send_fragmented(5, "RIGHT", right);
  const std::vector<LcmDatagram> l = parse_all(left_datagrams);
  const std::vector<LcmDatagram> r = parse_all(right_datagrams);
  ASSERT_EQ(l.size(), 3u);
  ASSERT_EQ(r.size(), 3u);

  LcmReassembler reassembler(1 << 20);
  const std::uint64_t a = 0x0a000001'3039;  // senders: address and port
  const std::uint64_t b = 0x0a000002'3039;
  EXPECT_EQ(reassembler.add(a, l[0]), Outcome::pending);
  EXPECT_EQ(reassembler.add(b, r[0]), Outcome::pending);
  EXPECT_EQ(reassembler.add(b, r[1]), Outcome::pending);
  EXPECT_EQ(reassembler.add(a, l[1]), Outcome::pending);
  EXPECT_EQ(reassembler.messages_held(), 2u);
  EXPECT_EQ(reassembler.bytes_held(), left.size() + right.size());
  ASSERT_EQ(reassembler.add(a, l[2]), Outcome::complete);
  EXPECT_EQ(reassembler.channel(), "LEFT");
  EXPECT_TRUE(same(reassembler.payload(), left));
  EXPECT_EQ(reassembler.bytes_held(), right.size());
  ASSERT_EQ(reassembler.add(b, r[2]), Outcome::complete);
  EXPECT_EQ(reassembler.channel(), "RIGHT");
  EXPECT_TRUE(same(reassembler.payload(), right));
  EXPECT_EQ(reassembler.bytes_held(), 0u);
  EXPECT_EQ(reassembler.abandoned(), 0u);
}

TEST(LcmReassembler, HoldsAtMostMaxSendersMessagesEvictingTheLeastRecentlyTouched) {
  constexpr std::size_t kExtra = 10;
  const Bytes payload = pattern(100, 4);
  const std::span<const std::uint8_t> whole(payload);
  LcmReassembler reassembler(100);
  for (std::uint64_t sender = 0; sender < LcmReassembler::kMaxSenders + kExtra; ++sender) {
    EXPECT_EQ(reassembler.add(sender, make_fragment(1, 100, 0, 0, 2, whole.first(50), "s")), Outcome::pending);
    EXPECT_LE(reassembler.messages_held(), LcmReassembler::kMaxSenders);
  }
  EXPECT_EQ(reassembler.messages_held(), LcmReassembler::kMaxSenders);
  EXPECT_EQ(reassembler.abandoned(), kExtra);
  EXPECT_EQ(reassembler.bytes_held(), LcmReassembler::kMaxSenders * 100);

  const auto second = make_fragment(1, 100, 50, 1, 2, whole.subspan(50));
  // The newest and the oldest kept sender still finish ...
  EXPECT_EQ(reassembler.add(LcmReassembler::kMaxSenders + kExtra - 1, second), Outcome::complete);
  EXPECT_TRUE(same(reassembler.payload(), payload));
  EXPECT_EQ(reassembler.add(kExtra, second), Outcome::complete);
  // ... the first ones were evicted: their second fragment starts a message that lacks fragment 0.
  EXPECT_EQ(reassembler.add(0, second), Outcome::pending);
  EXPECT_EQ(reassembler.abandoned(), kExtra);
}

TEST(LcmReassembler, StaysWithinByteBudgetEvictingTheLeastRecentlyTouched) {
  // Two messages of the limit fit the budget (kMinBudget here), a third does not.
  const std::size_t limit = LcmReassembler::kMinBudget * 3 / 8;
  const auto size = static_cast<std::uint32_t>(limit);
  const Bytes slice = pattern(1);
  LcmReassembler reassembler(limit);
  ASSERT_EQ(reassembler.add(1, make_fragment(1, size, 0, 0, 3, slice, "one")), Outcome::pending);
  ASSERT_EQ(reassembler.add(2, make_fragment(1, size, 0, 0, 3, slice, "two")), Outcome::pending);
  ASSERT_EQ(reassembler.add(1, make_fragment(1, size, 1, 1, 3, slice)), Outcome::pending);  // 1 is touched last
  EXPECT_EQ(reassembler.bytes_held(), 2 * limit);
  ASSERT_EQ(reassembler.add(3, make_fragment(1, size, 0, 0, 3, slice, "three")), Outcome::pending);
  EXPECT_LE(reassembler.bytes_held(), LcmReassembler::kMinBudget);
  EXPECT_EQ(reassembler.bytes_held(), 2 * limit);
  EXPECT_EQ(reassembler.messages_held(), 2u);
  EXPECT_EQ(reassembler.abandoned(), 1u);
  // Sender 1 and 3 are still held (their fragment 0 again is a duplicate); sender 2 went.
  EXPECT_EQ(reassembler.add(1, make_fragment(1, size, 0, 0, 3, slice, "one")), Outcome::refused);
  EXPECT_EQ(reassembler.add(3, make_fragment(1, size, 0, 0, 3, slice, "three")), Outcome::refused);
  EXPECT_EQ(reassembler.add(2, make_fragment(1, size, 0, 0, 3, slice, "two")), Outcome::pending);
  EXPECT_LE(reassembler.bytes_held(), LcmReassembler::kMinBudget);
  EXPECT_EQ(reassembler.abandoned(), 2u);
}

TEST(LcmReassembler, OverlappingSlicesSummingToTheSizeAreRefusedNotDelivered) {
  const Bytes payload = pattern(10, 6);
  const std::span<const std::uint8_t> whole(payload);
  {
    // [0,6) and [2,6): 6 + 4 = 10 bytes received, [6,10) never written.
    LcmReassembler reassembler(100);
    ASSERT_EQ(reassembler.add(1, make_fragment(1, 10, 0, 0, 2, whole.first(6), "c")), Outcome::pending);
    EXPECT_EQ(reassembler.add(1, make_fragment(1, 10, 2, 1, 2, whole.subspan(2, 4))), Outcome::refused);
    EXPECT_EQ(reassembler.messages_held(), 0u);
    EXPECT_EQ(reassembler.bytes_held(), 0u);
    EXPECT_EQ(reassembler.abandoned(), 1u);
  }
  {
    // [0,4), [4,7), [5,8): 4 + 3 + 3 = 10, the gap [8,10) at the end.
    LcmReassembler reassembler(100);
    ASSERT_EQ(reassembler.add(1, make_fragment(1, 10, 0, 0, 3, whole.first(4), "c")), Outcome::pending);
    ASSERT_EQ(reassembler.add(1, make_fragment(1, 10, 5, 2, 3, whole.subspan(5, 3))), Outcome::pending);
    EXPECT_EQ(reassembler.add(1, make_fragment(1, 10, 4, 1, 3, whole.subspan(4, 3))), Outcome::refused);
    EXPECT_EQ(reassembler.bytes_held(), 0u);
    EXPECT_EQ(reassembler.abandoned(), 1u);
  }
  {
    // The same three fragments tiling the message: delivered.
    LcmReassembler reassembler(100);
    ASSERT_EQ(reassembler.add(1, make_fragment(1, 10, 0, 0, 3, whole.first(4), "c")), Outcome::pending);
    ASSERT_EQ(reassembler.add(1, make_fragment(1, 10, 7, 2, 3, whole.subspan(7))), Outcome::pending);
    ASSERT_EQ(reassembler.add(1, make_fragment(1, 10, 4, 1, 3, whole.subspan(4, 3))), Outcome::complete);
    EXPECT_TRUE(same(reassembler.payload(), payload));
    EXPECT_EQ(reassembler.abandoned(), 0u);
  }
}

}  // namespace
}  // namespace cosmic
