// The NRT fragmentation codec: header layout, Fragmenter, Reassembler (duplicates, gaps,
// reordering, interrupted sequences, timeouts, bounds, hostile input).
#include "cosmic/can_fragment.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <random>
#include <vector>

namespace cosmic {
namespace {

using std::chrono::milliseconds;
using Frame = std::vector<std::uint8_t>;

std::vector<std::uint8_t> pattern(std::size_t n, std::uint8_t seed = 0) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(seed + i * 7 + (i >> 8));
  return v;
}

std::vector<Frame> fragment(const std::vector<std::uint8_t>& event, std::uint32_t capacity, std::uint8_t sequence) {
  Fragmenter f(event, capacity, sequence);
  std::vector<Frame> frames;
  std::array<std::uint8_t, 64> buffer{};
  while (!f.done()) {
    const std::size_t n = f.next(buffer);
    frames.emplace_back(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
  }
  return frames;
}

Frame fragment_frame(std::uint8_t seq, bool last, std::uint16_t index, std::vector<std::uint8_t> data) {
  const std::uint16_t h = encode_fragment_header(FragmentHeader{seq, last, index});
  Frame f;
  f.reserve(2 + data.size());
  f.push_back(static_cast<std::uint8_t>(h >> 8));
  f.push_back(static_cast<std::uint8_t>(h & 0xFF));
  f.insert(f.end(), data.begin(), data.end());
  return f;
}

constexpr Nanos t0 = milliseconds(1000);

TEST(CanFragmentHeader, BitLayoutIsSequenceLastIndexBigEndian) {
  EXPECT_EQ(encode_fragment_header({5, true, 3}), 0x5803);
  EXPECT_EQ(encode_fragment_header({15, false, 2047}), 0xF7FF);
  EXPECT_EQ(encode_fragment_header({0, false, 0}), 0x0000);
  EXPECT_EQ(decode_fragment_header(0xA805), (FragmentHeader{10, true, 5}));
  for (std::uint8_t s = 0; s < 16; ++s) {
    for (std::uint16_t i : {0, 1, 170, 2047}) {
      for (bool last : {false, true}) {
        const FragmentHeader h{s, last, i};
        EXPECT_EQ(decode_fragment_header(encode_fragment_header(h)), h);
      }
    }
  }
  const auto frames = fragment(pattern(10), 8, 5);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0][0], 0x50);  // sequence 5, not last, index 0
  EXPECT_EQ(frames[0][1], 0x00);
  EXPECT_EQ(frames[1][0], 0x58);  // sequence 5, last, index 1
  EXPECT_EQ(frames[1][1], 0x01);
}

TEST(CanFragmentCount, MatchesAdmissionAndBounds) {
  EXPECT_TRUE(needs_fragmentation(9, 8));
  EXPECT_FALSE(needs_fragmentation(8, 8));
  EXPECT_FALSE(needs_fragmentation(64, 64));
  EXPECT_EQ(fragment_count(0, 8), 1u);
  EXPECT_EQ(fragment_count(6, 8), 1u);
  EXPECT_EQ(fragment_count(7, 8), 2u);
  EXPECT_EQ(fragment_count(1024, 8), 171u);
  EXPECT_EQ(fragment_count(1024, 64), 17u);
  EXPECT_EQ(fragment_count(1024, 8), fragments_needed(1024, 8));
  EXPECT_EQ(fragment_count(1024, 64), fragments_needed(1024, 64));
  EXPECT_EQ(fragment_count(10, 2), 0u);
  EXPECT_EQ(max_fragmented_event(8), 2048u * 6);
  EXPECT_EQ(max_fragmented_event(64), 2048u * 62);
}

TEST(CanFragmenter, CutsOneKibIntoFullFramesAndMarksOnlyTheLast) {
  const auto event = pattern(1024);
  const auto frames = fragment(event, 8, 3);
  ASSERT_EQ(frames.size(), 171u);
  std::vector<std::uint8_t> joined;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto h = decode_fragment_header(static_cast<std::uint16_t>((frames[i][0] << 8) | frames[i][1]));
    EXPECT_EQ(h.sequence, 3);
    EXPECT_EQ(h.index, i);
    EXPECT_EQ(h.last, i + 1 == frames.size());
    EXPECT_EQ(frames[i].size(), i + 1 == frames.size() ? 2u + 1024 % 6 : 8u);
    joined.insert(joined.end(), frames[i].begin() + 2, frames[i].end());
  }
  EXPECT_EQ(joined, event);
}

TEST(CanFragmenter, EmptyEventIsOneHeaderOnlyFragment) {
  const auto frames = fragment({}, 8, 0);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0], (Frame{0x08, 0x00}));
}

TEST(CanFragmenter, RefusesEventsBeyond2048FragmentsAndSmallBuffers) {
  const std::vector<std::uint8_t> huge(2048 * 6 + 1);
  Fragmenter f(huge, 8, 0);
  EXPECT_FALSE(f.valid());
  std::array<std::uint8_t, 8> buffer{};
  EXPECT_EQ(f.next(buffer), 0u);
  const std::vector<std::uint8_t> largest(2048 * 6);
  Fragmenter ok(largest, 8, 0);
  EXPECT_TRUE(ok.valid());
  EXPECT_EQ(ok.count(), 2048u);
  std::array<std::uint8_t, 4> small{};
  EXPECT_EQ(ok.next(small), 0u);  // buffer smaller than a frame: nothing written
  EXPECT_EQ(ok.next(buffer), 8u);
}

TEST(CanReassembler, ReassemblesInOrderEventsOfBothFrameSizes) {
  for (std::uint32_t capacity : {8u, 64u}) {
    Reassembler r;
    const auto event = pattern(1024, static_cast<std::uint8_t>(capacity));
    const auto frames = fragment(event, capacity, 9);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const auto result = r.accept(7, frames[i], 1024, t0);
      if (i + 1 < frames.size()) {
        ASSERT_EQ(result.outcome, FragmentOutcome::partial);
      } else {
        ASSERT_EQ(result.outcome, FragmentOutcome::complete);
        EXPECT_EQ(std::vector<std::uint8_t>(result.event.begin(), result.event.end()), event);
      }
    }
    EXPECT_EQ(r.counters().completed, 1u);
    EXPECT_EQ(r.counters().dropped_events(), 0u);
    EXPECT_EQ(r.pending(), 0u);
  }
}

TEST(CanReassembler, SingleFragmentEventIsAViewOfTheFrame) {
  Reassembler r;
  const Frame f = fragment_frame(0, true, 0, {1, 2, 3});
  const auto result = r.accept(1, f, 100, t0);
  ASSERT_EQ(result.outcome, FragmentOutcome::complete);
  EXPECT_EQ(result.event.data(), f.data() + 2);
  EXPECT_EQ(result.event.size(), 3u);
}

TEST(CanReassembler, DuplicatesAreIgnored) {
  Reassembler r;
  const auto event = pattern(20);
  const auto frames = fragment(event, 8, 1);  // 4 fragments
  int complete = 0;
  for (const auto& f : frames) {
    for (int twice = 0; twice < 2; ++twice) {
      const auto result = r.accept(1, f, 20, t0);
      if (result.outcome == FragmentOutcome::complete) {
        ++complete;
        EXPECT_EQ(std::vector<std::uint8_t>(result.event.begin(), result.event.end()), event);
      }
      if (twice == 1) {
        EXPECT_EQ(result.outcome, FragmentOutcome::ignored);
      }
    }
  }
  EXPECT_EQ(complete, 1);
  EXPECT_EQ(r.counters().duplicates, 4u);
  EXPECT_EQ(r.counters().dropped_events(), 0u);
  // A repeated single-fragment event is recognised too.
  const Frame single = fragment_frame(2, true, 0, {9});
  EXPECT_EQ(r.accept(1, single, 20, t0).outcome, FragmentOutcome::complete);
  EXPECT_EQ(r.accept(1, single, 20, t0).outcome, FragmentOutcome::ignored);
}

TEST(CanReassembler, GapDropsTheEventAndItsRestIsDiscarded) {
  Reassembler r;
  const auto frames = fragment(pattern(30), 8, 4);  // 5 fragments
  EXPECT_EQ(r.accept(1, frames[0], 30, t0).outcome, FragmentOutcome::partial);
  const auto gap = r.accept(1, frames[2], 30, t0);  // 1 lost
  EXPECT_EQ(gap.outcome, FragmentOutcome::rejected);
  EXPECT_TRUE(gap.dropped_event);
  EXPECT_EQ(r.accept(1, frames[3], 30, t0).outcome, FragmentOutcome::ignored);
  EXPECT_EQ(r.accept(1, frames[4], 30, t0).outcome, FragmentOutcome::ignored);
  EXPECT_EQ(r.counters().gaps, 1u);
  EXPECT_EQ(r.counters().stray, 2u);
  EXPECT_EQ(r.counters().completed, 0u);
  EXPECT_EQ(r.pending(), 0u);
  // The next event of the source is fine.
  const auto next = fragment(pattern(30, 1), 8, 5);
  FragmentResult last;
  for (const auto& f : next) last = r.accept(1, f, 30, t0);
  EXPECT_EQ(last.outcome, FragmentOutcome::complete);
}

TEST(CanReassembler, MissingFirstFragmentIsAGap) {
  Reassembler r;
  const auto frames = fragment(pattern(30), 8, 4);
  const auto result = r.accept(1, frames[1], 30, t0);
  EXPECT_EQ(result.outcome, FragmentOutcome::rejected);
  EXPECT_TRUE(result.dropped_event);
  EXPECT_EQ(r.counters().gaps, 1u);
  for (std::size_t i = 2; i < frames.size(); ++i)
    EXPECT_EQ(r.accept(1, frames[i], 30, t0).outcome, FragmentOutcome::ignored);
  EXPECT_EQ(r.counters().gaps, 1u);  // one lost event, counted once
}

TEST(CanReassembler, ReorderedFragmentsDropTheEvent) {
  Reassembler r;
  const auto frames = fragment(pattern(30), 8, 6);  // 5 fragments
  r.accept(1, frames[0], 30, t0);
  r.accept(1, frames[2], 30, t0);  // overtakes 1
  const auto late = r.accept(1, frames[1], 30, t0);
  EXPECT_EQ(late.outcome, FragmentOutcome::ignored);
  r.accept(1, frames[3], 30, t0);
  r.accept(1, frames[4], 30, t0);
  EXPECT_EQ(r.counters().completed, 0u);
  EXPECT_EQ(r.counters().gaps, 1u);
  EXPECT_EQ(r.counters().reordered, 1u);
}

TEST(CanReassembler, NewSequenceBeforeTheEndDropsThePartialAndStartsOver) {
  Reassembler r;
  const auto first = fragment(pattern(30), 8, 1);
  const auto second = fragment(pattern(30, 9), 8, 2);
  r.accept(1, first[0], 30, t0);
  r.accept(1, first[1], 30, t0);
  const auto restart = r.accept(1, second[0], 30, t0);
  EXPECT_TRUE(restart.dropped_event);
  EXPECT_EQ(restart.outcome, FragmentOutcome::partial);
  FragmentResult last;
  for (std::size_t i = 1; i < second.size(); ++i) last = r.accept(1, second[i], 30, t0);
  ASSERT_EQ(last.outcome, FragmentOutcome::complete);
  EXPECT_EQ(std::vector<std::uint8_t>(last.event.begin(), last.event.end()), pattern(30, 9));
  EXPECT_EQ(r.counters().interrupted, 1u);
}

TEST(CanReassembler, SourcesAreIndependentWhenInterleaved) {
  Reassembler r;
  const auto a = fragment(pattern(40, 1), 8, 0);
  const auto b = fragment(pattern(40, 2), 8, 0);
  int complete = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::uint32_t source : {1u, 2u}) {
      const auto result = r.accept(source, source == 1 ? a[i] : b[i], 40, t0);
      if (result.outcome == FragmentOutcome::complete) {
        ++complete;
        EXPECT_EQ(std::vector<std::uint8_t>(result.event.begin(), result.event.end()),
                  pattern(40, static_cast<std::uint8_t>(source)));
      }
    }
  }
  EXPECT_EQ(complete, 2);
}

TEST(CanReassembler, IdlePartialsTimeOut) {
  Reassembler r(ReassemblyLimits{4, milliseconds(100), 0});
  const auto frames = fragment(pattern(30), 8, 1);
  r.accept(1, frames[0], 30, t0);
  r.accept(2, frames[0], 30, t0 + milliseconds(50));
  EXPECT_EQ(r.next_deadline(), t0 + milliseconds(100));
  std::vector<std::uint32_t> dropped;
  EXPECT_EQ(r.expire(t0 + milliseconds(120), [&](std::uint32_t s) { dropped.push_back(s); }), 1u);
  EXPECT_EQ(dropped, std::vector<std::uint32_t>{1});
  EXPECT_EQ(r.pending(), 1u);
  // Found stale on access too (without expire()).
  const auto late = r.accept(2, frames[1], 30, t0 + milliseconds(200));
  EXPECT_TRUE(late.dropped_event);
  EXPECT_EQ(r.counters().timeouts, 2u);
  // Progress keeps a slow event alive: the timeout is per fragment, not per event.
  Reassembler slow(ReassemblyLimits{4, milliseconds(100), 0});
  FragmentResult last;
  for (std::size_t i = 0; i < frames.size(); ++i) last = slow.accept(1, frames[i], 30, t0 + milliseconds(90 * i));
  EXPECT_EQ(last.outcome, FragmentOutcome::complete);
}

TEST(CanReassembler, RecordsOfFinishedEventsExpireSoARebootedSourceIsHeard) {
  Reassembler r(ReassemblyLimits{4, milliseconds(100), 0});
  const auto frames = fragment(pattern(20), 8, 0);
  for (const auto& f : frames) r.accept(1, f, 20, t0);
  // Same sequence again right away: duplicates. Much later: a new event (the node restarted).
  EXPECT_EQ(r.accept(1, frames[0], 20, t0 + milliseconds(1)).outcome, FragmentOutcome::ignored);
  FragmentResult last;
  for (const auto& f : frames) last = r.accept(1, f, 20, t0 + milliseconds(500));
  EXPECT_EQ(last.outcome, FragmentOutcome::complete);
}

TEST(CanReassembler, BoundedNumberOfPartialsEvictsTheOldest) {
  Reassembler r(ReassemblyLimits{3, milliseconds(100), 0});
  const auto frames = fragment(pattern(30), 8, 0);
  for (std::uint32_t s = 1; s <= 3; ++s) r.accept(s, frames[0], 30, t0 + milliseconds(s));
  const auto fourth = r.accept(4, frames[0], 30, t0 + milliseconds(10));
  EXPECT_EQ(fourth.outcome, FragmentOutcome::partial);
  ASSERT_TRUE(fourth.displaced.has_value());
  EXPECT_EQ(*fourth.displaced, 1u);
  EXPECT_EQ(r.counters().evicted, 1u);
  EXPECT_EQ(r.pending(), 3u);
  // Source 1's rest is a gap now; sources 2..4 complete.
  EXPECT_EQ(r.accept(1, frames[1], 30, t0 + milliseconds(11)).outcome, FragmentOutcome::rejected);
  int complete = 0;
  for (std::uint32_t s = 2; s <= 4; ++s) {
    for (std::size_t i = 1; i < frames.size(); ++i) {
      complete += r.accept(s, frames[i], 30, t0 + milliseconds(12)).outcome == FragmentOutcome::complete;
    }
  }
  EXPECT_EQ(complete, 3);
}

TEST(CanReassembler, EventsLargerThanTheChannelAreDropped) {
  Reassembler r;
  const auto frames = fragment(pattern(30), 8, 0);  // 30 bytes on a channel of 20
  FragmentResult result;
  std::size_t i = 0;
  for (; i < frames.size(); ++i) {
    result = r.accept(1, frames[i], 20, t0);
    if (result.outcome != FragmentOutcome::partial) break;
  }
  EXPECT_EQ(i, 3u);  // 18 bytes fit, the 4th fragment would make 24
  EXPECT_EQ(result.outcome, FragmentOutcome::rejected);
  EXPECT_EQ(r.counters().oversize, 1u);
  for (++i; i < frames.size(); ++i) EXPECT_EQ(r.accept(1, frames[i], 20, t0).outcome, FragmentOutcome::ignored);
  // One oversize single fragment.
  const Frame big = fragment_frame(1, true, 0, {1, 2, 3, 4, 5, 6});
  EXPECT_EQ(r.accept(1, big, 5, t0).outcome, FragmentOutcome::rejected);
  EXPECT_EQ(r.counters().oversize, 2u);
}

TEST(CanReassembler, FdPaddingOfTheLastFragmentIsCutOff) {
  Reassembler r(ReassemblyLimits{4, milliseconds(100), 15});
  // 100 bytes on FD: 62 + 38; the last frame (40 B) is padded to 48 on the wire.
  auto frames = fragment(pattern(100), 64, 0);
  ASSERT_EQ(frames.size(), 2u);
  frames[1].resize(48, 0);
  r.accept(1, frames[0], 100, t0);
  const auto result = r.accept(1, frames[1], 100, t0);
  ASSERT_EQ(result.outcome, FragmentOutcome::complete);
  EXPECT_EQ(std::vector<std::uint8_t>(result.event.begin(), result.event.end()), pattern(100));
  // Padding is not allowed in the middle of an event.
  Reassembler strict(ReassemblyLimits{4, milliseconds(100), 15});
  const auto middle = fragment_frame(0, false, 0, std::vector<std::uint8_t>(62 + 10));
  EXPECT_EQ(strict.accept(1, middle, 70, t0).outcome, FragmentOutcome::rejected);
}

TEST(CanReassembler, HostileFramesNeverOverrun) {
  Reassembler r(ReassemblyLimits{4, milliseconds(100), 0});
  EXPECT_EQ(r.accept(1, Frame{}, 100, t0).outcome, FragmentOutcome::rejected);
  EXPECT_EQ(r.accept(1, Frame{0x00}, 100, t0).outcome, FragmentOutcome::rejected);
  EXPECT_EQ(r.counters().malformed, 2u);
  // An index beyond what the channel can have: a gap, nothing stored.
  EXPECT_EQ(r.accept(1, fragment_frame(0, false, 2047, {1, 2}), 100, t0).outcome, FragmentOutcome::rejected);
  // 2047 fragments of 0 bytes then a non-last index 2047 (no index 2048 exists): oversize.
  for (std::uint16_t i = 0; i < 2047; ++i) {
    ASSERT_EQ(r.accept(2, fragment_frame(3, false, i, {}), 100, t0).outcome, FragmentOutcome::partial);
  }
  EXPECT_EQ(r.accept(2, fragment_frame(3, false, 2047, {}), 100, t0).outcome, FragmentOutcome::rejected);
  EXPECT_EQ(r.counters().oversize, 1u);

  // Random frames from random sources: no crash, bounded state, counters add up.
  std::mt19937 rng(42);
  Reassembler fuzz(ReassemblyLimits{8, milliseconds(100), 15});
  std::uint64_t complete = 0;
  for (int n = 0; n < 200000; ++n) {
    Frame f(rng() % 65);
    for (auto& b : f) b = static_cast<std::uint8_t>(rng());
    if (f.size() >= 2 && rng() % 2) f[1] = static_cast<std::uint8_t>(f[1] & 0x07);  // small indexes more often
    const auto result = fuzz.accept(rng() % 12, f, rng() % 300, t0 + milliseconds(n / 100));
    if (result.outcome == FragmentOutcome::complete) {
      ++complete;
      ASSERT_LE(result.event.size(), 300u);
    }
    ASSERT_LE(fuzz.pending(), 8u);
  }
  EXPECT_EQ(fuzz.counters().completed, complete);
  EXPECT_GT(fuzz.counters().dropped_events() + fuzz.counters().malformed, 0u);
}

}  // namespace
}  // namespace cosmic
