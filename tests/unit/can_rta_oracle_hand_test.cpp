// CanBusAnalysis and the independent oracle of can_rta_oracle.hpp against response times
// computed by hand: how standard and extended identifiers arbitrate (equal base bits, lower
// base bits, equal bases compared on their low bits, equal identifiers) and a level at exactly
// 100 % in every input order. The randomized comparisons are in can_rta_oracle_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "can_rta_oracle.hpp"
#include "cosmic/can_timing.hpp"

namespace cosmic::can_rta_test {
namespace {

using namespace std::chrono_literals;

// ================================================================ hand-computed arbitration cases

// 500 kbit/s: tau_bit = 2 us; classic frames (bits * 2 us): standard 0 B = 55 bits = 110 us,
// standard 8 B = 135 bits = 270 us, extended 0 B = 80 bits = 160 us, extended 4 B = 120 bits =
// 240 us, extended 8 B = 160 bits = 320 us. Every period 10 ms, no jitter: each busy period is
// below 2 ms, so Q = 1 and every ceiling below is 1. With no hp stream, w = B (+ E).
TestBus hand_bus(std::vector<std::pair<OracleStream, std::uint32_t>> frames, CanFaultHypothesis errors = {}) {
  TestBus bus;
  bus.properties.bitrate = BitRate{500'000};
  bus.properties.errors = errors;
  for (auto& [stream, payload] : frames) {
    stream.transmission = frame_time(bus.properties, payload, stream.format).count();
    stream.period = 10 * kMs;
    bus.streams.push_back(stream);
  }
  return bus;
}

void expect_both(const TestBus& bus, const std::vector<std::optional<Nanos>>& by_hand) {
  EXPECT_EQ(library_results(bus), by_hand) << describe(bus);
  EXPECT_EQ(oracle_results(bus), by_hand) << describe(bus);
}

constexpr auto kStd = CanIdFormat::standard11;
constexpr auto kExt = CanIdFormat::extended29;

// std 0x100 (0 B, 110 us) against ext 0x04000005 (base 0x100, 8 B, 320 us); std 0x700 (8 B,
// 270 us) below both. Standard wins the tie on the base bits:
//   std 0x100: B = max(320, 270) = 320            -> R = 320 + 110 = 430 us
//   ext:       B = 270, hp = {110}                -> R = 270 + 110 + 320 = 700 us
//   std 0x700: B = 0, hp = {110, 320}             -> R = 430 + 270 = 700 us
// (Had the extended frame won: 590, 700, 700.)
TEST(CanRtaOracle, StandardBeatsExtendedWithEqualBaseBits) {
  expect_both(hand_bus({{{0x100, kStd}, 0}, {{0x04000005, kExt}, 8}, {{0x700, kStd}, 8}}),
              {Nanos(430us), Nanos(700us), Nanos(700us)});
}

// ext 0x00000001 (base 0, 8 B, 320 us) against std 0x7FF (0 B, 110 us); ext 0x1FFFFFFF (base
// 0x7FF, loses to the standard frame, 4 B, 240 us) below both. The lower base wins:
//   ext 0x1:   B = max(110, 240) = 240            -> R = 240 + 320 = 560 us
//   std 0x7FF: B = 240, hp = {320}                -> R = 240 + 320 + 110 = 670 us
//   ext 0x1FFFFFFF: B = 0, hp = {320, 110}        -> R = 430 + 240 = 670 us
// (A rule "standard always first" would give 670, 350, 670.)
TEST(CanRtaOracle, LowerBaseBitsWinWhateverTheFormat) {
  expect_both(hand_bus({{{0x00000001, kExt}, 8}, {{0x7FF, kStd}, 0}, {{0x1FFFFFFF, kExt}, 4}}),
              {Nanos(560us), Nanos(670us), Nanos(670us)});
}

// ext 0x04000002 (8 B, 320 us) and ext 0x04000001 (0 B, 160 us): same base, the low 18 bits
// decide; std 0x7FF (8 B, 270 us) below. One error per 10 ms: error frame 31 bits = 62 us, so
// E = 62 us + the longest hep frame for any interval up to 10 ms.
//   ext ..01: B = max(320, 270) = 320, hep max 160, E = 222 -> w = 542, R = 542 + 160 = 702 us
//   ext ..02: B = 270, hp = {160}, hep max 320, E = 382 -> w = 270 + 382 + 160 = 812,
//             R = 812 + 320 = 1132 us
//   std 0x7FF: B = 0, hp = {160, 320}, E = 382 -> w = 862, R = 862 + 270 = 1132 us
// (With ..02 winning: ..02 = 270 + 382 + 320 = 972 us, ..01 = 1132 us.)
TEST(CanRtaOracle, ExtendedFramesWithEqualBaseCompareTheirLowBits) {
  expect_both(hand_bus({{{0x04000002, kExt}, 8}, {{0x04000001, kExt}, 0}, {{0x7FF, kStd}, 8}}, {1, Nanos(10ms)}),
              {Nanos(1132us), Nanos(702us), Nanos(1132us)});
}

// Equal identifiers (one channel's two hops): one level, each blocks the other, neither
// interferes: std 0x200 8 B (270 us) and std 0x200 0 B (110 us): R = 110 + 270 = 380 us both.
// (As interference instead: 110 + 110 + 270 = 490 us for the long one.)
TEST(CanRtaOracle, EqualIdentifiersOnlyBlockEachOther) {
  expect_both(hand_bus({{{0x200, kStd}, 8}, {{0x200, kStd}, 0}}), {Nanos(380us), Nanos(380us)});
}

// ================================================================ a level at exactly 100 %

// Found by this oracle: a level at exactly 100 % was decided by floating-point rounding, in an
// order that followed the input list; the library now decides it in exact integers. Three
// standard frames at 1 Mbit/s, every T = 1 ms, no jitter, no faults: 0x001 C = 100 us, 0x002
// C = 200 us, 0x003 C = 700 us. By hand: 0x001: B = 700, R = 800 us; 0x002: B = 700, hp = {100},
// R = 1000 us; 0x003: load 0.1 + 0.2 + 0.7 = 1 exactly: unbounded (the library's own rule,
// "utilization >= 100 %"). The library sums loads in doubles: 1.0 in priority order, within its
// 1e-9 margin, so it re-sums in input order, own stream first: 0.7 + 0.1 + 0.2 = 1.0 (unbounded)
// when 0x001 comes before 0x002 in the input, 0.7 + 0.2 + 0.1 = 0.9999999999999999 when 0x002
// comes first; below 1 its busy period ends at 1 ms (B = 0, no jitter) and it answers R = 1 ms.
// So the verdict of 0x003 followed the order of the input list (3 of the 6 orders failed).
// Ten frames of C = 100 us, T = 1 ms (0.1 ten times) sum to 0.9999999999999999 in doubles in any
// order: the tenth frame's level is exactly full too.
TEST(CanRtaOracle, AnExactlyFullLevelIsUnboundedInEveryInputOrder) {
  TestBus bus;
  bus.properties.bitrate = BitRate{1'000'000};
  bus.streams = {{0x001, kStd, 100'000, kMs, 0}, {0x002, kStd, 200'000, kMs, 0}, {0x003, kStd, 700'000, kMs, 0}};
  const auto by_id = [](const OracleStream& a, const OracleStream& b) { return a.id < b.id; };
  do {  // every order of the input list
    std::vector<std::optional<Nanos>> by_hand;
    for (const OracleStream& s : bus.streams) {
      by_hand.push_back(s.id == 1 ? std::optional<Nanos>(800us) : s.id == 2 ? std::optional<Nanos>(1ms) : std::nullopt);
    }
    EXPECT_EQ(oracle_results(bus), by_hand) << describe(bus);
    EXPECT_EQ(library_results(bus), by_hand) << describe(bus);
  } while (std::next_permutation(bus.streams.begin(), bus.streams.end(), by_id));
  TestBus tenths;
  tenths.properties.bitrate = BitRate{1'000'000};
  for (std::uint32_t id = 1; id <= 10; ++id) tenths.streams.push_back({id, kStd, 100'000, kMs, 0});
  EXPECT_EQ(oracle_results(tenths).back(), std::nullopt);
  EXPECT_EQ(library_results(tenths).back(), std::nullopt) << "library: " << show(library_results(tenths).back());
}

}  // namespace
}  // namespace cosmic::can_rta_test
