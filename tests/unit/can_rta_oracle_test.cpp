// Randomized comparisons of CanBusAnalysis with the independent oracle of can_rta_oracle.hpp
// on buses that mix 11-bit and 29-bit identifiers (fresh analyses and analyses reusing a
// previous one), and a discrete-event simulation whose observed responses must stay within the
// bound (DESIGN.md §4 and §10). The hand-computed cases are in can_rta_oracle_hand_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "can_rta_oracle.hpp"
#include "cosmic/can_timing.hpp"

namespace cosmic::can_rta_test {
namespace {

// Every stream's result equal to the nanosecond; returns how many streams disagreed.
std::size_t count_disagreements(const TestBus& bus, const std::vector<std::optional<Nanos>>& library,
                                const std::vector<std::optional<Nanos>>& oracle, const char* what) {
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < oracle.size(); ++i) {
    if (library[i] == oracle[i]) continue;
    ++wrong;
    ADD_FAILURE() << what << ": stream " << i << " library " << show(library[i]) << " oracle " << show(oracle[i])
                  << "\n"
                  << describe(bus);
  }
  return wrong;
}

// ================================================================ random buses

class Dice {
 public:
  explicit Dice(std::uint64_t seed) : engine_(seed) {}
  // Uniform-enough integer in [low, high]; mt19937_64 is specified, so every platform agrees.
  std::int64_t between(std::int64_t low, std::int64_t high) {
    return low + static_cast<std::int64_t>(engine_() % static_cast<std::uint64_t>(high - low + 1));
  }
  bool percent(int chance) { return between(0, 99) < chance; }
  std::size_t index(std::size_t size) {
    return static_cast<std::size_t>(between(0, static_cast<std::int64_t>(size) - 1));
  }

 private:
  std::mt19937_64 engine_;
};

constexpr std::array<std::uint64_t, 4> kBitRates{125'000, 250'000, 500'000, 1'000'000};

// A few 11-bit bases per bus, so that standard and extended identifiers collide on them.
std::vector<std::uint32_t> random_bases(Dice& dice) {
  std::vector<std::uint32_t> bases{0, 0x7FF};
  const std::int64_t count = dice.between(1, 6);
  for (std::int64_t i = 0; i < count; ++i) bases.push_back(static_cast<std::uint32_t>(dice.between(0, 0x7FF)));
  return bases;
}

std::uint32_t random_low_bits(Dice& dice) {
  constexpr std::array<std::uint32_t, 4> kEdges{0, 1, 2, 0x3FFFF};
  if (dice.percent(60)) return kEdges[dice.index(kEdges.size())];
  return static_cast<std::uint32_t>(dice.between(0, 0x3FFFF));
}

// Identifier and format: often a copy of an existing one, usually on one of the shared bases.
void random_identifier(Dice& dice, const std::vector<OracleStream>& so_far, const std::vector<std::uint32_t>& bases,
                       OracleStream& s) {
  if (!so_far.empty() && dice.percent(15)) {
    const OracleStream& twin = so_far[dice.index(so_far.size())];
    s.id = twin.id;
    s.format = twin.format;
    return;
  }
  const auto base =
      dice.percent(75) ? bases[dice.index(bases.size())] : static_cast<std::uint32_t>(dice.between(0, 0x7FF));
  s.format = dice.percent(50) ? CanIdFormat::standard11 : CanIdFormat::extended29;
  s.id = s.format == CanIdFormat::standard11 ? base : base << 18 | random_low_bits(dice);
}

std::int64_t random_period(Dice& dice) {
  return dice.percent(50) ? dice.between(1, 200) * kMs : dice.between(1 * kMs, 200 * kMs);
}

std::int64_t random_jitter(Dice& dice, std::int64_t period) {
  const std::int64_t kind = dice.between(0, 19);
  if (kind < 8) return 0;
  if (kind < 14) return dice.between(0, period / 10);
  if (kind < 19) return dice.between(0, period);
  return period;
}

OracleStream random_stream(Dice& dice, const TestBus& bus, const std::vector<std::uint32_t>& bases) {
  OracleStream s;
  random_identifier(dice, bus.streams, bases, s);
  const auto payload = static_cast<std::uint32_t>(dice.between(0, 8));
  s.transmission = frame_time(bus.properties, payload, s.format).count();
  s.period = random_period(dice);
  s.jitter = random_jitter(dice, s.period);
  return s;
}

// Half the buses without faults; N = 0 with a window must also switch the term off.
void random_fault_hypothesis(Dice& dice, CanSegmentProperties& properties) {
  if (dice.percent(50)) return;
  properties.errors.max_per_window = static_cast<std::uint32_t>(dice.between(0, 3));
  properties.errors.window = Nanos(dice.between(10 * kMs, 100 * kMs));
}

// Bus load with every stream and the fault term of the longest frame.
double whole_bus_load(const TestBus& bus) {
  double load = 0.0;
  std::int64_t longest = 0;
  for (const OracleStream& s : bus.streams) {
    load += static_cast<double>(s.transmission) / static_cast<double>(s.period);
    longest = std::max(longest, s.transmission);
  }
  const CanBusTiming timing = bus_timing(bus.properties);
  if (timing.errors.max_per_window == 0) return load;
  return load + timing.errors.max_per_window * static_cast<double>(timing.error_frame_time.count() + longest) /
                    static_cast<double>(timing.errors.window.count());
}

// Light and heavy buses stay below `ceiling` by dropping their last streams; an overloaded bus
// keeps all of them and, if it came out light, gets its periods halved (not below 1 ms) until
// it passes 110 %.
void shape_load(TestBus& bus, double ceiling, bool overload) {
  if (!overload) {
    while (bus.streams.size() > 1 && whole_bus_load(bus) >= ceiling) bus.streams.pop_back();
    return;
  }
  bool shortened = true;
  while (shortened && whole_bus_load(bus) < 1.1) {
    shortened = false;
    for (OracleStream& s : bus.streams) {
      shortened = shortened || s.period > kMs;
      s.period = std::max(kMs, s.period / 2);
      s.jitter = std::min(s.jitter, s.period);
    }
  }
}

TestBus random_bus(Dice& dice, std::vector<std::uint32_t>& bases) {
  TestBus bus;
  bus.properties.bitrate = BitRate{kBitRates[dice.index(kBitRates.size())]};
  random_fault_hypothesis(dice, bus.properties);
  bases = random_bases(dice);
  const std::int64_t count = dice.percent(30) ? dice.between(1, 5) : dice.between(1, 40);
  for (std::int64_t i = 0; i < count; ++i) bus.streams.push_back(random_stream(dice, bus, bases));
  const std::int64_t kind = dice.between(0, 9);
  shape_load(bus, kind < 5 ? 0.7 : 0.97, kind == 9);
  return bus;
}

struct Tally {
  std::size_t buses = 0, streams = 0, unbounded = 0, disagreements = 0;
  void add(const std::vector<std::optional<Nanos>>& oracle, std::size_t wrong) {
    ++buses;
    streams += oracle.size();
    disagreements += wrong;
    unbounded += static_cast<std::size_t>(std::count(oracle.begin(), oracle.end(), std::nullopt));
  }
  void print(const char* what) const {
    std::printf("[ oracle   ] %s: %zu buses, %zu streams (%zu unbounded), %zu disagreements\n", what, buses, streams,
                unbounded, disagreements);
  }
};

TEST(CanRtaOracle, RandomMixedIdentifierBusesMatchTheOracle) {
  Dice dice(20070101);
  std::vector<std::uint32_t> bases;
  Tally tally;
  for (int i = 0; i < 2500; ++i) {
    const TestBus bus = random_bus(dice, bases);
    const auto oracle = oracle_results(bus);
    tally.add(oracle, count_disagreements(bus, library_results(bus), oracle, "fresh analysis"));
  }
  tally.print("fresh analysis");
  EXPECT_EQ(tally.disagreements, 0u);
  EXPECT_GT(tally.unbounded, 0u);  // overloaded levels were exercised
}

TEST(CanRtaOracle, ReuseOfPreviousAnalysisWithNewcomerMatchesFreshAndOracle) {
  Dice dice(35);
  std::vector<std::uint32_t> bases;
  Tally tally;
  std::size_t reused_streams = 0;
  for (int i = 0; i < 2000; ++i) {
    const TestBus before = random_bus(dice, bases);
    TestBus after = before;
    const OracleStream newcomer = random_stream(dice, before, bases);
    after.streams.insert(after.streams.begin() + dice.between(0, static_cast<std::int64_t>(before.streams.size())),
                         newcomer);
    const CanBusTiming timing = bus_timing(before.properties);
    const CanBusAnalysis previous(library_streams(before.streams), timing);
    const CanBusAnalysis reused(library_streams(after.streams), timing, &previous);
    const CanBusAnalysis fresh(library_streams(after.streams), timing);
    EXPECT_EQ(reused.results(), fresh.results()) << describe(after);
    EXPECT_LE(reused.analysed(), fresh.analysed());
    reused_streams += fresh.analysed() - reused.analysed();
    const auto oracle = oracle_results(after);
    tally.add(oracle, count_disagreements(after, reused.results(), oracle, "reused analysis"));
  }
  tally.print("reused analysis");
  std::printf("[ oracle   ] %zu stream results taken from the previous analysis\n", reused_streams);
  EXPECT_EQ(tally.disagreements, 0u);
  EXPECT_GT(reused_streams, 0u);
}

// ================================================================ discrete-event check

// Non-preemptive fixed priority: whenever the bus goes idle, of the frames released by then the
// one that wins arbitration is sent whole. Every stream releases at 0 (the critical instant) and
// then every T. Returns each stream's longest observed response (release to end of frame).
std::vector<std::int64_t> simulated_worst_responses(std::span<const OracleStream> streams, std::int64_t horizon) {
  std::vector<std::int64_t> oldest_release(streams.size(), 0);
  std::vector<std::int64_t> worst(streams.size(), 0);
  std::int64_t now = 0;
  while (now < horizon) {
    std::optional<std::size_t> winner;
    for (std::size_t i = 0; i < streams.size(); ++i) {
      if (oldest_release[i] > now) continue;
      if (!winner || arbitrate(streams[i], streams[*winner]) == Arbitration::first_wins) winner = i;
    }
    if (!winner) {  // idle until the next release
      now = *std::min_element(oldest_release.begin(), oldest_release.end());
      continue;
    }
    now += streams[*winner].transmission;
    worst[*winner] = std::max(worst[*winner], now - oldest_release[*winner]);
    oldest_release[*winner] += streams[*winner].period;
  }
  return worst;
}

bool identifier_taken(const TestBus& bus, const OracleStream& s) {
  return std::any_of(bus.streams.begin(), bus.streams.end(),
                     [&](const OracleStream& o) { return arbitrate(o, s) == Arbitration::same_identifier; });
}

// Periods dividing 200 ms (hyperperiod 200 ms), distinct identifiers, no jitter, no faults,
// bus load below 90 %.
TestBus random_simulation_bus(Dice& dice) {
  constexpr std::array<std::int64_t, 12> kPeriodsMs{1, 2, 4, 5, 8, 10, 20, 25, 40, 50, 100, 200};
  TestBus bus;
  bus.properties.bitrate = BitRate{kBitRates[dice.index(kBitRates.size())]};
  const std::vector<std::uint32_t> bases = random_bases(dice);
  const std::int64_t count = dice.between(2, 8);
  for (std::int64_t i = 0; i < count; ++i) {
    OracleStream s = random_stream(dice, bus, bases);
    if (identifier_taken(bus, s)) continue;
    s.jitter = 0;
    s.period = kPeriodsMs[dice.index(kPeriodsMs.size())] * kMs;
    bus.streams.push_back(s);
    if (whole_bus_load(bus) >= 0.9) bus.streams.pop_back();
  }
  return bus;
}

TEST(CanRtaOracle, SimulatedResponsesNeverExceedTheBound) {
  Dice dice(4242);
  std::size_t frames_checked = 0;
  for (int i = 0; i < 60; ++i) {
    const TestBus bus = random_simulation_bus(dice);
    const auto bounds = library_results(bus);
    const auto observed = simulated_worst_responses(bus.streams, 400 * kMs);  // two hyperperiods
    for (std::size_t s = 0; s < bus.streams.size(); ++s) {
      ASSERT_TRUE(bounds[s].has_value()) << describe(bus);
      EXPECT_LE(observed[s], bounds[s]->count()) << "stream " << s << "\n" << describe(bus);
      EXPECT_GE(observed[s], bus.streams[s].transmission);  // every stream was sent at least once
      ++frames_checked;
    }
    EXPECT_EQ(oracle_results(bus), bounds) << describe(bus);
  }
  std::printf("[ oracle   ] simulation: %zu streams on 60 buses\n", frames_checked);
}

}  // namespace
}  // namespace cosmic::can_rta_test
