// A second, independent CAN worst-case response-time analysis used as a test oracle for
// CanBusAnalysis, and randomized comparisons of the two on buses that mix 11-bit and 29-bit
// identifiers (DESIGN.md §4 and §10).
//
// The oracle is written from Davis, Burns, Bril and Lukkien 2007 (sufficient test, busy period,
// every instance q) and is deliberately naive: no prefix sums, no release thresholds, no reuse;
// every iteration walks every higher-priority stream. It orders frames by its own reading of the
// CAN arbitration field, bit by bit, and never calls arbitration_key().
//
//   R_m    = J_m + max over q in [0, Q_m) of (w_m(q) - q T_m + C_m)
//   w_m(q) = B_m + q C_m + E(w_m(q) + C_m) + sum_{k in hp(m)} ceil((w_m(q) + J_k + tau_bit) / T_k) C_k
//   t_m    = B_m + E(t_m) + sum_{k in hep(m)} ceil((t_m + J_k) / T_k) C_k,   t_m starts at C_m
//   Q_m    = ceil((t_m + J_m) / T_m)
//
// Fault hypothesis, as the library's error_overhead() applies it: at most N error frames in any
// window W, each followed by the retransmission of the longest frame of hep(m):
//   E(x) = ceil(x / W) * N * (error_frame_time + max_{k in hep(m)} C_k),  0 when N = 0 or W <= 0.
//
// Equal identifiers (two hops of one channel share one): the library makes them one level where
// none interferes with another and each blocks the others (they count in B_m, not in hp(m), nor
// in hep(m) of the busy period and the error term). The oracle mirrors that: hp(m) = streams
// that win arbitration against m, B_m = max C over the other streams.
//
// Unbounded (nullopt) when the level's load sum_{hep} C/T + N (error_frame_time + max C) / W is
// >= 1 (exact rational arithmetic here) or a recurrence passes 100 s (the library's horizon).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/can_timing.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

// ================================================================ the oracle

struct OracleStream {
  std::uint32_t id = 0;
  CanIdFormat format = CanIdFormat::standard11;
  std::int64_t transmission = 0;  // C, ns
  std::int64_t period = 0;        // T, ns
  std::int64_t jitter = 0;        // J, ns
};

// tau_bit, the error frame's time, at most N error frames in any window W (ns).
struct OracleBus {
  std::int64_t bit_time = 0, error_frame_time = 0, errors_per_window = 0, error_window = 0;
};

constexpr std::int64_t kGiveUpHorizon = 100'000'000'000;  // 100 s, as the library

// The arbitration field as it goes on the wire, 0 = dominant. Standard: ID10..ID0, RTR, IDE.
// Extended: ID28..ID18, SRR, IDE, ID17..ID0, RTR. Data frames: RTR dominant.
struct ArbitrationBits {
  std::array<std::uint8_t, 32> bits{};
  std::size_t length = 0;
  void send(std::uint32_t bit) { bits[length++] = static_cast<std::uint8_t>(bit & 1u); }
  void send_id_bits(std::uint32_t id, int from, int to) { for (int b = from; b >= to; --b) send(id >> b); }
};

ArbitrationBits arbitration_bits(const OracleStream& s) {
  ArbitrationBits field;
  if (s.format == CanIdFormat::standard11) {
    field.send_id_bits(s.id, 10, 0);
    field.send(0);  // RTR
    field.send(0);  // IDE: standard
  } else {
    field.send_id_bits(s.id, 28, 18);
    field.send(1);  // SRR: recessive
    field.send(1);  // IDE: extended
    field.send_id_bits(s.id, 17, 0);
    field.send(0);  // RTR
  }
  return field;
}

enum class Arbitration { first_wins, second_wins, same_identifier };

// The first differing bit decides: the node sending dominant keeps the bus.
Arbitration arbitrate(const OracleStream& first, const OracleStream& second) {
  const ArbitrationBits a = arbitration_bits(first);
  const ArbitrationBits b = arbitration_bits(second);
  for (std::size_t i = 0; i < std::min(a.length, b.length); ++i) {
    if (a.bits[i] != b.bits[i]) return a.bits[i] == 0 ? Arbitration::first_wins : Arbitration::second_wins;
  }
  return Arbitration::same_identifier;
}

std::int64_t ceiling_of(std::int64_t numerator, std::int64_t denominator) {
  if (numerator <= 0) return 0;
  return numerator / denominator + (numerator % denominator != 0 ? 1 : 0);
}

// What stream m's recurrences see of the rest of the bus.
struct OracleLevel {
  const OracleStream* self = nullptr;
  std::vector<const OracleStream*> higher;  // hp(m)
  std::int64_t blocking = 0;                // B_m
  std::int64_t longest_hep_frame = 0;       // max C over hep(m)
};

OracleLevel level_of(std::span<const OracleStream> bus, std::size_t m) {
  OracleLevel level;
  level.self = &bus[m];
  level.longest_hep_frame = bus[m].transmission;
  for (std::size_t k = 0; k < bus.size(); ++k) {
    if (k == m) continue;
    if (arbitrate(bus[k], bus[m]) == Arbitration::first_wins) {
      level.higher.push_back(&bus[k]);
      level.longest_hep_frame = std::max(level.longest_hep_frame, bus[k].transmission);
    } else {
      level.blocking = std::max(level.blocking, bus[k].transmission);
    }
  }
  return level;
}

std::int64_t error_recovery(std::int64_t interval, const OracleLevel& level, const OracleBus& bus) {
  if (bus.errors_per_window == 0 || bus.error_window <= 0) return 0;
  return ceiling_of(interval, bus.error_window) * bus.errors_per_window *
         (bus.error_frame_time + level.longest_hep_frame);
}

// ---------------------------------------------------------------- exact load of a level

__extension__ typedef __int128 Wide;

Wide greatest_common_divisor(Wide a, Wide b) {
  while (b != 0) a = std::exchange(b, a % b);
  return a;
}

struct Fraction { Wide numerator = 0, denominator = 1; };

// a + n/d, or nullopt when the exact value no longer fits 127 bits.
std::optional<Fraction> plus(Fraction a, std::int64_t n, std::int64_t d) {
  const Wide g = greatest_common_divisor(a.denominator, d);
  Fraction sum;
  Wide left = 0;
  Wide right = 0;
  if (__builtin_mul_overflow(a.denominator / g, Wide{d}, &sum.denominator)) return std::nullopt;
  if (__builtin_mul_overflow(a.numerator, Wide{d} / g, &left)) return std::nullopt;
  if (__builtin_mul_overflow(Wide{n}, a.denominator / g, &right)) return std::nullopt;
  if (__builtin_add_overflow(left, right, &sum.numerator)) return std::nullopt;
  const Wide common = greatest_common_divisor(sum.numerator, sum.denominator);  // >= 1: d > 0
  return Fraction{sum.numerator / common, sum.denominator / common};
}

struct LoadTerm { std::int64_t numerator, denominator; };

std::vector<LoadTerm> load_terms(const OracleLevel& level, const OracleBus& bus) {
  std::vector<LoadTerm> terms{{level.self->transmission, level.self->period}};
  for (const OracleStream* k : level.higher) terms.push_back({k->transmission, k->period});
  if (bus.errors_per_window > 0 && bus.error_window > 0) {
    terms.push_back({bus.errors_per_window * (bus.error_frame_time + level.longest_hep_frame), bus.error_window});
  }
  return terms;
}

// Load >= 1, exactly. Periods of many streams make a denominator past 127 bits; the sum then
// falls back to long double, which cannot tell 1 from its neighbours: that would be a failure.
bool level_overloaded(const OracleLevel& level, const OracleBus& bus) {
  const std::vector<LoadTerm> terms = load_terms(level, bus);
  std::optional<Fraction> exact = Fraction{};
  long double approximate = 0.0L;
  for (const LoadTerm& term : terms) {
    if (exact) exact = plus(*exact, term.numerator, term.denominator);
    approximate += static_cast<long double>(term.numerator) / static_cast<long double>(term.denominator);
  }
  if (exact) return exact->numerator >= exact->denominator;
  if (std::fabs(approximate - 1.0L) < 1e-12L) ADD_FAILURE() << "oracle cannot decide a load of " << static_cast<double>(approximate);
  return approximate >= 1.0L;
}

// ---------------------------------------------------------------- recurrences

std::int64_t higher_priority_demand(const OracleLevel& level, std::int64_t interval, std::int64_t offset) {
  std::int64_t demand = 0;
  for (const OracleStream* k : level.higher) demand += ceiling_of(interval + k->jitter + offset, k->period) * k->transmission;
  return demand;
}

std::optional<std::int64_t> oracle_busy_period(const OracleLevel& level, const OracleBus& bus) {
  const OracleStream& m = *level.self;
  std::int64_t t = m.transmission;
  while (true) {
    const std::int64_t demand = level.blocking + error_recovery(t, level, bus) +
                                ceiling_of(t + m.jitter, m.period) * m.transmission +
                                higher_priority_demand(level, t, 0);
    if (demand == t) return t;
    if (demand > kGiveUpHorizon) return std::nullopt;
    t = demand;
  }
}

std::optional<std::int64_t> oracle_queuing_delay(const OracleLevel& level, const OracleBus& bus, std::int64_t q) {
  const OracleStream& m = *level.self;
  std::int64_t w = level.blocking + q * m.transmission;
  while (true) {
    const std::int64_t next = level.blocking + q * m.transmission + error_recovery(w + m.transmission, level, bus) +
                              higher_priority_demand(level, w, bus.bit_time);
    if (next == w) return w;
    if (next > kGiveUpHorizon) return std::nullopt;
    w = next;
  }
}

std::optional<Nanos> oracle_response_time(std::span<const OracleStream> streams, std::size_t m, const OracleBus& bus) {
  const OracleLevel level = level_of(streams, m);
  if (level_overloaded(level, bus)) return std::nullopt;
  const auto busy = oracle_busy_period(level, bus);
  if (!busy) return std::nullopt;
  const OracleStream& self = streams[m];
  const std::int64_t instances = ceiling_of(*busy + self.jitter, self.period);
  std::int64_t worst = 0;
  for (std::int64_t q = 0; q < instances; ++q) {
    const auto w = oracle_queuing_delay(level, bus, q);
    if (!w) return std::nullopt;
    worst = std::max(worst, self.jitter + *w - q * self.period + self.transmission);
  }
  return Nanos(worst);
}

std::vector<std::optional<Nanos>> oracle_response_times(std::span<const OracleStream> streams, const OracleBus& bus) {
  std::vector<std::optional<Nanos>> results;
  for (std::size_t m = 0; m < streams.size(); ++m) results.push_back(oracle_response_time(streams, m, bus));
  return results;
}

// ================================================================ both analyses on one bus

struct TestBus {
  CanSegmentProperties properties;
  std::vector<OracleStream> streams;
};

OracleBus oracle_bus(const CanBusTiming& timing) {
  return OracleBus{timing.bit_time.count(), timing.error_frame_time.count(),
                   static_cast<std::int64_t>(timing.errors.max_per_window), timing.errors.window.count()};
}

std::vector<CanStream> library_streams(std::span<const OracleStream> streams) {
  std::vector<CanStream> out;
  for (const OracleStream& s : streams)
    out.push_back(CanStream{arbitration_key(s.id, s.format), Nanos(s.transmission), Nanos(s.period), Nanos(s.jitter)});
  return out;
}

std::vector<std::optional<Nanos>> oracle_results(const TestBus& bus) {
  return oracle_response_times(bus.streams, oracle_bus(bus_timing(bus.properties)));
}
std::vector<std::optional<Nanos>> library_results(const TestBus& bus) {
  return CanBusAnalysis(library_streams(bus.streams), bus_timing(bus.properties)).results();
}

std::string describe(const TestBus& bus) {
  std::ostringstream out;
  out << "bitrate " << bus.properties.bitrate.bits_per_second << ", errors " << bus.properties.errors.max_per_window
      << " per " << bus.properties.errors.window.count() << " ns\n";
  for (const OracleStream& s : bus.streams) {
    out << "  " << (s.format == CanIdFormat::standard11 ? "std 0x" : "ext 0x") << std::hex << s.id << std::dec
        << " C " << s.transmission << " T " << s.period << " J " << s.jitter << "\n";
  }
  return out.str();
}

std::string show(const std::optional<Nanos>& r) { return r ? std::to_string(r->count()) : std::string("unbounded"); }

// Every stream's result equal to the nanosecond; returns how many streams disagreed.
std::size_t count_disagreements(const TestBus& bus, const std::vector<std::optional<Nanos>>& library,
                                const std::vector<std::optional<Nanos>>& oracle, const char* what) {
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < oracle.size(); ++i) {
    if (library[i] == oracle[i]) continue;
    ++wrong;
    ADD_FAILURE() << what << ": stream " << i << " library " << show(library[i]) << " oracle " << show(oracle[i]) << "\n"
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
  std::size_t index(std::size_t size) { return static_cast<std::size_t>(between(0, static_cast<std::int64_t>(size) - 1)); }

 private:
  std::mt19937_64 engine_;
};

constexpr std::array<std::uint64_t, 4> kBitRates{125'000, 250'000, 500'000, 1'000'000};
constexpr std::int64_t kMs = 1'000'000;

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
  const auto base = dice.percent(75) ? bases[dice.index(bases.size())] : static_cast<std::uint32_t>(dice.between(0, 0x7FF));
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
    after.streams.insert(after.streams.begin() + dice.between(0, static_cast<std::int64_t>(before.streams.size())), newcomer);
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
}  // namespace cosmic
