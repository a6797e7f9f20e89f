// The native CAN format and the bus census (issue 19, items 2 and 3), without a CAN bus: what the
// adapter's receive and send paths use.
#include <gtest/gtest.h>

#include "bus_census.hpp"
#include "native_frames.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

TEST(NativeFrames, IdentifiersMatchExactlyByFormatAndNeverAsRemoteRequests) {
  can_native::FrameTable table;
  ASSERT_TRUE(table.add_publisher(NativeCanFrame{0x123, false}, can_native::RxChannel{7, 0x42, 4}));
  ASSERT_TRUE(table.add_publisher(NativeCanFrame{0x123, true}, can_native::RxChannel{8, 0x43, 8}));
  EXPECT_FALSE(table.add_publisher(NativeCanFrame{0x123, false}, can_native::RxChannel{9, 0x44, 4}));  // one sender
  table.add_subscriber(NativeCanFrame{0x7FF, false});
  table.add_background(CanBackgroundFrame{"Engine", 0x0C0, false, 8, Nanos(10ms), Nanos(0), "test", std::nullopt});
  ASSERT_NE(table.find(0x123), nullptr);
  EXPECT_EQ(table.find(0x123)->id, 7u);
  EXPECT_EQ(table.find(0x123 | CAN_EFF_FLAG)->id, 8u);
  EXPECT_EQ(table.find(0x123 | CAN_RTR_FLAG), nullptr);
  EXPECT_EQ(table.find(0x124), nullptr);
  EXPECT_TRUE(table.is_background(0x0C0));
  EXPECT_FALSE(table.is_background(0x0C0 | CAN_EFF_FLAG));
  EXPECT_TRUE(table.explains(0x7FF));
  EXPECT_TRUE(table.explains(0x123 | CAN_EFF_FLAG));
  EXPECT_FALSE(table.explains(0x0A0));
  // Kernel filters: the identifier, its format and the RTR bit all have to match.
  const auto filters = table.filters();
  ASSERT_EQ(filters.size(), 2u);
  for (const can_filter& f : filters) {
    EXPECT_TRUE(f.can_mask & CAN_RTR_FLAG);
    EXPECT_TRUE(f.can_mask & CAN_EFF_FLAG);
    EXPECT_EQ(f.can_mask & CAN_EFF_MASK, (f.can_id & CAN_EFF_FLAG) ? CAN_EFF_MASK : CAN_SFF_MASK);
  }
}

TEST(NativeFrames, ContentsAreTheDataBytesWithFdPaddingCut) {
  const can_native::RxChannel channel{7, 0x42, 10};
  const std::uint8_t data[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(can_native::contents(channel, std::span(data, 3), false)->size(), 3u);
  EXPECT_EQ(can_native::contents(channel, std::span(data, 12), true)->size(), 10u);  // 10 B padded to 12
  EXPECT_FALSE(can_native::contents(channel, std::span(data, 16), true));            // longer than the padded payload
  EXPECT_FALSE(can_native::contents(can_native::RxChannel{7, 0x42, 4}, std::span(data, 5), false));
}

TEST(NativeFrames, AnEventIsOneFrameWithTheIdentifier) {
  const std::uint8_t payload[5] = {0xA, 0xB, 0xC, 0xD, 0xE};
  const canfd_frame classic = can_native::encode(NativeCanFrame{0x123, false}, payload, false, false);
  EXPECT_EQ(classic.can_id, 0x123u);
  EXPECT_EQ(classic.len, 5u);
  EXPECT_EQ(classic.flags, 0u);
  EXPECT_EQ(classic.data[4], 0xE);
  const canfd_frame fd = can_native::encode(NativeCanFrame{0x18FF1234, true}, std::span(payload, 5), true, true);
  EXPECT_EQ(fd.can_id, 0x18FF1234u | CAN_EFF_FLAG);
  EXPECT_EQ(fd.len, 5u);  // 5 is an FD length
  EXPECT_EQ(fd.flags, CANFD_BRS);
  const std::uint8_t nine[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  const canfd_frame padded = can_native::encode(NativeCanFrame{0x100, false}, nine, true, false);
  EXPECT_EQ(padded.len, 12u);
  EXPECT_EQ(padded.data[9], 0);
  EXPECT_EQ(padded.data[11], 0);
}

TEST(BusCensus, CountsByIdentifierWithRatesLowestIdentifierFirst) {
  can_census::BusCensus census;
  const Nanos t0 = Nanos(5s);
  for (int i = 0; i < 100; ++i) census.count(0x0A0, t0 + i * Nanos(10ms));  // 100 Hz
  census.count(0x1ABCFF00 | CAN_EFF_FLAG, t0);
  census.count(0x7FF, t0);
  census.count(0x0A0, t0 + Nanos(1s));  // the first window ends: its rate stands
  auto seen = census.snapshot(t0 + Nanos(1s));
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0], (UnexplainedFrames{0x0A0, false, 101, 100.0}));
  // Extended 0x1ABCFF00 (base bits 0x6AF) wins arbitration over standard 0x7FF.
  EXPECT_EQ(seen[1].can_id, 0x1ABCFF00u);
  EXPECT_TRUE(seen[1].extended);
  EXPECT_EQ(seen[2].can_id, 0x7FFu);
  EXPECT_DOUBLE_EQ(seen[2].rate_hz, 1.0);  // one frame in its first window so far
  // Silent for two windows: rate 0, frames kept.
  seen = census.snapshot(t0 + Nanos(4s));
  EXPECT_EQ(seen[0].frames, 101u);
  EXPECT_EQ(seen[0].rate_hz, 0.0);
}

TEST(BusCensus, IsBoundedAndSumsTheRest) {
  can_census::BusCensus census;
  for (canid_t id = 0; id < can_census::BusCensus::kMaxIdentifiers + 10; ++id) census.count(id, Nanos(1s));
  EXPECT_EQ(census.snapshot(Nanos(1s)).size(), can_census::BusCensus::kMaxIdentifiers);
  EXPECT_EQ(census.others(), 10u);
  census.clear();
  EXPECT_TRUE(census.snapshot(Nanos(1s)).empty());
}

}  // namespace
}  // namespace cosmic
