// Duplicate filter (serial-number arithmetic, bounded window, restart recovery) and the raw-mode
// loop guard, driven directly with chosen sequences and times.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "cosmic/router_policy.hpp"

namespace cosmic {
namespace {

constexpr std::uint64_t kOrigin = 0x0717;

// Feeds sequences first..last (inclusive, wrapping modulo 2^32) and counts those taken as seen.
std::uint64_t feed(DuplicateFilter& f, std::uint32_t first, std::uint32_t count) {
  std::uint64_t duplicates = 0;
  for (std::uint32_t i = 0; i < count; ++i) duplicates += f.seen(kOrigin, first + i) ? 1 : 0;
  return duplicates;
}

TEST(DuplicateFilterTest, RepeatsInsideTheWindowAreDuplicatesAndReorderingIsNot) {
  DuplicateFilter f;
  EXPECT_FALSE(f.seen(kOrigin, 10));
  EXPECT_TRUE(f.seen(kOrigin, 10));
  EXPECT_FALSE(f.seen(kOrigin, 12));
  EXPECT_FALSE(f.seen(kOrigin, 11));  // late but new
  EXPECT_TRUE(f.seen(kOrigin, 11));
  EXPECT_FALSE(f.seen(kOrigin, 12 - DuplicateFilter::kWindow + 1));  // oldest slot of the window
  EXPECT_TRUE(f.seen(kOrigin, 12 - DuplicateFilter::kWindow + 1));
  EXPECT_FALSE(f.seen(kOrigin + 1, 10));  // another origin has its own window
  EXPECT_EQ(f.resyncs(), 0u);
}

TEST(DuplicateFilterTest, OneSpoofedMaximumSequenceDoesNotPoisonTheOrigin) {
  DuplicateFilter f;
  EXPECT_EQ(feed(f, 1, 10), 0u);
  f.seen(kOrigin, 0xFFFFFFFF);
  EXPECT_EQ(feed(f, 11, 200), 0u);    // every later genuine event still passes
  EXPECT_TRUE(f.seen(kOrigin, 210));  // and real duplicates are still caught
}

TEST(DuplicateFilterTest, ASpoofHalfTheSequenceSpaceAwayDoesNotPoisonTheOrigin) {
  for (const std::uint32_t spoof : {0x80000000u, 0x8000000Au, 0x80000010u, 0x7FFFFFFFu}) {
    DuplicateFilter f;
    EXPECT_EQ(feed(f, 1, 10), 0u);
    f.seen(kOrigin, spoof);
    EXPECT_EQ(feed(f, 11, 200), 0u) << std::hex << spoof;
    EXPECT_TRUE(f.seen(kOrigin, 200)) << std::hex << spoof;  // duplicates still caught
  }
}

TEST(DuplicateFilterTest, AGenuineWrapAfterTwoToThe32EventsIsOneStepForward) {
  DuplicateFilter f;
  EXPECT_EQ(feed(f, 0xFFFFFF00u, 0x100 + 300), 0u);  // ... 0xFFFFFFFF, 0, 1, ... 299
  EXPECT_EQ(f.resyncs(), 0u);
  EXPECT_TRUE(f.seen(kOrigin, 299));
  EXPECT_TRUE(f.seen(kOrigin, 280));
}

TEST(DuplicateFilterTest, DuplicatesAcrossTheWrapAreCaught) {
  DuplicateFilter f;
  EXPECT_EQ(feed(f, 0xFFFFFFF0u, 32), 0u);  // 0xFFFFFFF0 .. 0x0F
  EXPECT_TRUE(f.seen(kOrigin, 0xFFFFFFFEu));
  EXPECT_TRUE(f.seen(kOrigin, 0xFFFFFFFFu));
  EXPECT_TRUE(f.seen(kOrigin, 0u));
  EXPECT_FALSE(f.seen(kOrigin, 0x10u));
}

TEST(DuplicateFilterTest, AnOriginThatRestartsItsSequenceIsFollowedAndCounted) {
  DuplicateFilter f;
  EXPECT_EQ(feed(f, 1, 1000), 0u);
  EXPECT_EQ(feed(f, 1, 50), 0u);  // restart: sequence jumps far back to 1
  EXPECT_EQ(f.resyncs(), 1u);
  EXPECT_TRUE(f.seen(kOrigin, 50));  // the new window works as before
  EXPECT_EQ(feed(f, 51, 10), 0u);
}

TEST(DuplicateFilterTest, FarForwardJumpsPassAndAreCounted) {
  DuplicateFilter f;
  EXPECT_FALSE(f.seen(kOrigin, 1));
  EXPECT_FALSE(f.seen(kOrigin, 1 + DuplicateFilter::kMaxGap));  // a long outage, still counted as normal
  EXPECT_EQ(f.resyncs(), 0u);
  EXPECT_FALSE(f.seen(kOrigin, 2 + 2 * DuplicateFilter::kMaxGap));
  EXPECT_EQ(f.resyncs(), 1u);
}

TEST(DuplicateFilterTest, TheLeastRecentlyUsedOriginIsEvicted) {
  DuplicateFilter f;
  for (std::uint64_t origin = 1; origin <= 16; ++origin) EXPECT_FALSE(f.seen(origin, 5));
  EXPECT_TRUE(f.seen(1, 5));    // origin 1 is now the most recent
  EXPECT_FALSE(f.seen(17, 5));  // evicts origin 2
  EXPECT_FALSE(f.seen(2, 5));   // forgotten: new again
  EXPECT_TRUE(f.seen(1, 5));
}

std::vector<std::uint8_t> payload(std::uint8_t tag, std::size_t size = 8) {
  return std::vector<std::uint8_t>(size, tag);
}

TEST(RawLoopGuardTest, APayloadSeenAgainWithinTheWindowIsALoopCopy) {
  RawLoopGuard guard(Nanos(1'000'000));
  const auto p = payload(1);
  EXPECT_FALSE(guard.loop_copy(p, Nanos(10'000'000)));
  EXPECT_TRUE(guard.loop_copy(p, Nanos(10'500'000)));
}

TEST(RawLoopGuardTest, TheSamePayloadAfterTheWindowIsNew) {
  RawLoopGuard guard(Nanos(1'000'000));
  const auto p = payload(1);
  EXPECT_FALSE(guard.loop_copy(p, Nanos(10'000'000)));
  EXPECT_FALSE(guard.loop_copy(p, Nanos(11'000'000)));  // exactly one window later
  EXPECT_TRUE(guard.loop_copy(p, Nanos(11'999'999)));
}

TEST(RawLoopGuardTest, DifferentPayloadsAndLengthsAreNotConfused) {
  RawLoopGuard guard(Nanos(1'000'000));
  EXPECT_FALSE(guard.loop_copy(payload(1), Nanos(0)));
  EXPECT_FALSE(guard.loop_copy(payload(2), Nanos(1)));
  EXPECT_FALSE(guard.loop_copy(payload(1, 9), Nanos(2)));
  EXPECT_FALSE(guard.loop_copy(payload(0, 0), Nanos(3)));
  EXPECT_FALSE(guard.loop_copy(payload(0, 1), Nanos(4)));
  EXPECT_TRUE(guard.loop_copy(payload(0, 0), Nanos(5)));
}

TEST(RawLoopGuardTest, MemoryIsBoundedToTheLastEntries) {
  RawLoopGuard guard(Nanos(1'000'000'000));
  for (std::size_t i = 0; i <= RawLoopGuard::kEntries; ++i) {
    EXPECT_FALSE(guard.loop_copy(payload(static_cast<std::uint8_t>(i)), Nanos(static_cast<std::int64_t>(i))));
  }
  // The first payload was overwritten by the (kEntries + 1)-th: its copy passes (a documented
  // limit); the most recent one is still remembered.
  EXPECT_FALSE(guard.loop_copy(payload(0), Nanos(1000)));
  EXPECT_TRUE(guard.loop_copy(payload(static_cast<std::uint8_t>(RawLoopGuard::kEntries)), Nanos(1001)));
}

}  // namespace
}  // namespace cosmic
