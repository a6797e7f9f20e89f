// The CAN wire format units (lib/adapters/can/src/can_frame_format.hpp) without a bus: what each
// writes for an event and reads back, and what each refuses at configure().
#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "can_frame_format.hpp"
#include "cosmic/can_fragment.hpp"
#include "cosmic/can_wire.hpp"

namespace cosmic::can_detail {
namespace {

constexpr CanReassemblyBounds kBounds{4, Nanos(1'000'000'000)};
constexpr CanBus kClassic{8, false, false};
constexpr CanBus kFd{64, true, true};

class Collect final : public CanFrameBatchSink {
 public:
  explicit Collect(std::size_t refuse_after = ~std::size_t{0}) : refuse_after_(refuse_after) {}
  bool take(std::span<const canfd_frame> frames) override {
    if (batches == refuse_after_) return false;
    ++batches;
    frames_.insert(frames_.end(), frames.begin(), frames.end());
    return true;
  }
  const std::vector<canfd_frame>& frames() const { return frames_; }
  std::size_t batches = 0;

 private:
  std::size_t refuse_after_;
  std::vector<canfd_frame> frames_;
};

std::vector<std::uint8_t> bytes(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  std::iota(v.begin(), v.end(), std::uint8_t{1});
  return v;
}

// Every frame of `frames` into a fresh receiver; the event the last one completes.
template <typename Format>
std::optional<std::vector<std::uint8_t>> decode_all(Format receiver, const CanRxBinding& rx,
                                                    const std::vector<canfd_frame>& frames, bool fd) {
  CanRxBinding binding = rx;
  binding.format = &receiver;
  std::optional<std::vector<std::uint8_t>> event;
  for (const canfd_frame& f : frames) {
    const CanDecoded r = receiver.decode(binding, f.can_id, std::span<const std::uint8_t>(f.data, f.len), fd, Nanos(1));
    EXPECT_FALSE(r.lost);
    if (r.event) event.emplace(r.event->begin(), r.event->end());
  }
  return event;
}

TEST(CanFrameFormat, CosmicSingleFramesAndFragmentsRoundTripOnFd) {
  CosmicFrames format(kFd, kBounds);
  EXPECT_FALSE(format.fragments(64));
  EXPECT_TRUE(format.fragments(65));
  const CanTxBinding tx{1, &format, 0x0A05123, 0x0A05123, true, 0x123, 300, format.fragments(300)};
  const CanRxBinding rx{1, nullptr, 0x42, 300, true};
  EXPECT_TRUE(format.numbered(tx));
  for (std::size_t size : {0u, 62u, 63u, 64u, 200u, 300u}) {
    Collect sink;
    ASSERT_TRUE(format.encode(tx, bytes(size), 3, sink)) << size;
    EXPECT_EQ(sink.frames().size(), format.frame_count(tx, size)) << size;
    EXPECT_EQ(sink.frames().size(), fragment_count(size, 64)) << size;
    for (const canfd_frame& f : sink.frames()) {
      EXPECT_EQ(f.can_id, 0x0A05123u | CAN_EFF_FLAG);
      EXPECT_EQ(f.flags & CANFD_BRS, CANFD_BRS);
    }
    const auto event = decode_all(CosmicFrames(kFd, kBounds), rx, sink.frames(), true);
    ASSERT_TRUE(event) << size;
    EXPECT_EQ(*event, bytes(size)) << size;
  }
}

TEST(CanFrameFormat, CosmicSendsAnEventThatFitsOneFrameBare) {
  CosmicFrames format(kClassic, kBounds);
  const CanTxBinding tx{1, &format, 0x0A05123, 0x0A05123, true, 0x123, 8, false};
  EXPECT_FALSE(format.numbered(tx));
  EXPECT_EQ(format.frame_count(tx, 8), 1u);
  const canfd_frame f = format.single_frame(tx, bytes(5));
  EXPECT_EQ(f.len, 5);
  EXPECT_EQ(f.data[4], 5);
  EXPECT_EQ(f.flags, 0);
  // Longer than the channel allows: a decode error on the binding.
  const CanRxBinding rx{1, &format, 0x42, 4, false};
  const CanDecoded r = format.decode(rx, f.can_id, std::span<const std::uint8_t>(f.data, f.len), false, Nanos(1));
  EXPECT_TRUE(r.lost);
  EXPECT_FALSE(r.event);
}

TEST(CanFrameFormat, CosmicBatchesAFragmentedEventAndStopsAtTheFirstRefusedBatch) {
  CosmicFrames format(kClassic, kBounds);
  const CanTxBinding tx{1, &format, 0x0A05123, 0x0A05123, true, 0x123, 1024, true};
  Collect all;
  ASSERT_TRUE(format.encode(tx, bytes(1024), 0, all));
  EXPECT_EQ(all.frames().size(), 171u);  // 1024 B in 6-byte fragments
  EXPECT_EQ(all.batches, (171 + kFramesPerSubmit - 1) / kFramesPerSubmit);
  Collect refusing(2);
  EXPECT_FALSE(format.encode(tx, bytes(1024), 0, refusing));
  EXPECT_EQ(refusing.frames().size(), 2 * kFramesPerSubmit);
}

TEST(CanFrameFormat, CosmicRefusesWhatExceedsTheLastFragment) {
  CosmicFrames format(kClassic, kBounds);
  EXPECT_TRUE(format.check_payload(max_fragmented_event(8)).ok());
  const Result<void> beyond = format.check_payload(max_fragmented_event(8) + 1);
  ASSERT_FALSE(beyond.ok());
  EXPECT_NE(beyond.error().text.find("2048 fragments"), std::string::npos) << beyond.error().text;
}

TEST(CanFrameFormat, FamousoSendsUpToEightBytesPlainAndLongerEventsAsAfpUnderTheFlag) {
  FamousoFrames format(kBounds);
  const std::uint32_t id = 0x1E05123 & ~kFamousoFragmentFlag;
  const CanTxBinding tx{1, &format, id, id | kFamousoFragmentFlag, true, 0x123, 200, format.fragments(200)};
  const CanRxBinding rx{1, nullptr, 0x42, 200, true};
  EXPECT_FALSE(format.numbered(tx));
  for (std::size_t size : {0u, 8u, 9u, 62u, 200u}) {
    Collect sink;
    ASSERT_TRUE(format.encode(tx, bytes(size), 0, sink)) << size;
    EXPECT_EQ(sink.frames().size(), format.frame_count(tx, size)) << size;
    const bool afp = size > famouso::kAfpMtu;
    EXPECT_EQ(sink.frames().size() > 1, afp) << size;
    for (const canfd_frame& f : sink.frames()) {
      EXPECT_EQ((f.can_id & kFamousoFragmentFlag) != 0, afp) << size;
      EXPECT_LE(f.len, 8);
    }
    const auto event = decode_all(FamousoFrames(kBounds), rx, sink.frames(), false);
    ASSERT_TRUE(event) << size;
    EXPECT_EQ(*event, bytes(size)) << size;
  }
}

TEST(CanFrameFormat, FamousoLosesAnEventWhoseFragmentIsMissing) {
  FamousoFrames sender(kBounds);
  const CanTxBinding tx{1, &sender, 0x1E05123, 0x1E05123 | kFamousoFragmentFlag, true, 0x123, 40, true};
  Collect sink;
  ASSERT_TRUE(sender.encode(tx, bytes(40), 0, sink));
  ASSERT_GE(sink.frames().size(), 3u);
  FamousoFrames receiver(kBounds);
  const CanRxBinding rx{1, &receiver, 0x42, 40, true};
  const auto& f = sink.frames();
  EXPECT_FALSE(receiver.decode(rx, f[0].can_id, std::span(f[0].data, f[0].len), false, Nanos(1)).event);
  const CanDecoded gap = receiver.decode(rx, f[2].can_id, std::span(f[2].data, f[2].len), false, Nanos(2));
  EXPECT_TRUE(gap.lost);
  EXPECT_FALSE(gap.event);
  EXPECT_FALSE(receiver.next_deadline());  // nothing left waiting
}

TEST(CanFrameFormat, NativeIsOneFrameUnderTheDevicesIdentifierPaddedOnFd) {
  NativeFrames format(kFd);
  const CanTxBinding tx{1, &format, 0x3A0, 0x3A0, false, 0, 20, false};
  EXPECT_EQ(format.frame_count(tx, 20), 1u);
  EXPECT_FALSE(format.numbered(tx));
  Collect sink;
  ASSERT_TRUE(format.encode(tx, bytes(13), 0, sink));
  ASSERT_EQ(sink.frames().size(), 1u);
  const canfd_frame& f = sink.frames()[0];
  EXPECT_EQ(f.can_id, 0x3A0u);  // a standard identifier
  EXPECT_EQ(f.len, 16);         // the next CAN FD length
  const CanRxBinding rx{1, &format, 0x42, 20, false};
  const CanDecoded r = format.decode(rx, f.can_id, std::span<const std::uint8_t>(f.data, f.len), true, Nanos(1));
  ASSERT_TRUE(r.event);
  std::vector<std::uint8_t> expected = bytes(13);
  expected.resize(16, 0);  // the padding, up to the channel's 20 bytes
  EXPECT_EQ(std::vector<std::uint8_t>(r.event->begin(), r.event->end()), expected);
  EXPECT_FALSE(format.check_payload(65).ok());
  EXPECT_TRUE(format.check_payload(64).ok());
}

TEST(CanFrameFormat, NoFormatCarriesAnEventsIdentity) {
  CosmicFrames cosmic(kClassic, kBounds);
  FamousoFrames famouso(kBounds);
  NativeFrames native(kClassic);
  for (const CanFrameFormat* format :
       {static_cast<const CanFrameFormat*>(&cosmic), static_cast<const CanFrameFormat*>(&famouso),
        static_cast<const CanFrameFormat*>(&native)}) {
    EXPECT_EQ(format->identity(), (FormatIdentity{false, false, false, false})) << format->name();
  }
}

}  // namespace
}  // namespace cosmic::can_detail
