// A second, independent CAN worst-case response-time analysis used as a test oracle for
// CanBusAnalysis (DESIGN.md §4 and §10), and running both analyses on one test bus. Shared by
// can_rta_oracle_test.cpp (randomized comparisons on buses that mix 11-bit and 29-bit
// identifiers, a discrete-event check) and can_rta_oracle_hand_test.cpp (hand-computed cases).
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
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/can_timing.hpp"

namespace cosmic::can_rta_test {

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

inline constexpr std::int64_t kGiveUpHorizon = 100'000'000'000;  // 100 s, as the library

// The arbitration field as it goes on the wire, 0 = dominant. Standard: ID10..ID0, RTR, IDE.
// Extended: ID28..ID18, SRR, IDE, ID17..ID0, RTR. Data frames: RTR dominant.
struct ArbitrationBits {
  std::array<std::uint8_t, 32> bits{};
  std::size_t length = 0;
  void send(std::uint32_t bit) { bits[length++] = static_cast<std::uint8_t>(bit & 1u); }
  void send_id_bits(std::uint32_t id, int from, int to) {
    for (int b = from; b >= to; --b) send(id >> b);
  }
};

inline ArbitrationBits arbitration_bits(const OracleStream& s) {
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
inline Arbitration arbitrate(const OracleStream& first, const OracleStream& second) {
  const ArbitrationBits a = arbitration_bits(first);
  const ArbitrationBits b = arbitration_bits(second);
  for (std::size_t i = 0; i < std::min(a.length, b.length); ++i) {
    if (a.bits[i] != b.bits[i]) return a.bits[i] == 0 ? Arbitration::first_wins : Arbitration::second_wins;
  }
  return Arbitration::same_identifier;
}

inline std::int64_t ceiling_of(std::int64_t numerator, std::int64_t denominator) {
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

inline OracleLevel level_of(std::span<const OracleStream> bus, std::size_t m) {
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

inline std::int64_t error_recovery(std::int64_t interval, const OracleLevel& level, const OracleBus& bus) {
  if (bus.errors_per_window == 0 || bus.error_window <= 0) return 0;
  return ceiling_of(interval, bus.error_window) * bus.errors_per_window *
         (bus.error_frame_time + level.longest_hep_frame);
}

// ---------------------------------------------------------------- exact load of a level

__extension__ typedef __int128 Wide;

inline Wide greatest_common_divisor(Wide a, Wide b) {
  while (b != 0) a = std::exchange(b, a % b);
  return a;
}

struct Fraction {
  Wide numerator = 0, denominator = 1;
};

// a + n/d, or nullopt when the exact value no longer fits 127 bits.
inline std::optional<Fraction> plus(Fraction a, std::int64_t n, std::int64_t d) {
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

struct LoadTerm {
  std::int64_t numerator, denominator;
};

inline std::vector<LoadTerm> load_terms(const OracleLevel& level, const OracleBus& bus) {
  std::vector<LoadTerm> terms{{level.self->transmission, level.self->period}};
  for (const OracleStream* k : level.higher) terms.push_back({k->transmission, k->period});
  if (bus.errors_per_window > 0 && bus.error_window > 0) {
    terms.push_back({bus.errors_per_window * (bus.error_frame_time + level.longest_hep_frame), bus.error_window});
  }
  return terms;
}

// Load >= 1, exactly. Periods of many streams make a denominator past 127 bits; the sum then
// falls back to long double, which cannot tell 1 from its neighbours: that would be a failure.
inline bool level_overloaded(const OracleLevel& level, const OracleBus& bus) {
  const std::vector<LoadTerm> terms = load_terms(level, bus);
  std::optional<Fraction> exact = Fraction{};
  long double approximate = 0.0L;
  for (const LoadTerm& term : terms) {
    if (exact) exact = plus(*exact, term.numerator, term.denominator);
    approximate += static_cast<long double>(term.numerator) / static_cast<long double>(term.denominator);
  }
  if (exact) return exact->numerator >= exact->denominator;
  if (std::fabs(approximate - 1.0L) < 1e-12L)
    ADD_FAILURE() << "oracle cannot decide a load of " << static_cast<double>(approximate);
  return approximate >= 1.0L;
}

// ---------------------------------------------------------------- recurrences

inline std::int64_t higher_priority_demand(const OracleLevel& level, std::int64_t interval, std::int64_t offset) {
  std::int64_t demand = 0;
  for (const OracleStream* k : level.higher)
    demand += ceiling_of(interval + k->jitter + offset, k->period) * k->transmission;
  return demand;
}

inline std::optional<std::int64_t> oracle_busy_period(const OracleLevel& level, const OracleBus& bus) {
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

inline std::optional<std::int64_t> oracle_queuing_delay(const OracleLevel& level, const OracleBus& bus,
                                                        std::int64_t q) {
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

inline std::optional<Nanos> oracle_response_time(std::span<const OracleStream> streams, std::size_t m,
                                                 const OracleBus& bus) {
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

inline std::vector<std::optional<Nanos>> oracle_response_times(std::span<const OracleStream> streams,
                                                               const OracleBus& bus) {
  std::vector<std::optional<Nanos>> results;
  for (std::size_t m = 0; m < streams.size(); ++m) results.push_back(oracle_response_time(streams, m, bus));
  return results;
}

// ================================================================ both analyses on one bus

struct TestBus {
  CanSegmentProperties properties;
  std::vector<OracleStream> streams;
};

inline OracleBus oracle_bus(const CanBusTiming& timing) {
  return OracleBus{timing.bit_time.count(), timing.error_frame_time.count(),
                   static_cast<std::int64_t>(timing.errors.max_per_window), timing.errors.window.count()};
}

inline std::vector<CanStream> library_streams(std::span<const OracleStream> streams) {
  std::vector<CanStream> out;
  for (const OracleStream& s : streams)
    out.push_back(CanStream{arbitration_key(s.id, s.format), Nanos(s.transmission), Nanos(s.period), Nanos(s.jitter)});
  return out;
}

inline std::vector<std::optional<Nanos>> oracle_results(const TestBus& bus) {
  return oracle_response_times(bus.streams, oracle_bus(bus_timing(bus.properties)));
}
inline std::vector<std::optional<Nanos>> library_results(const TestBus& bus) {
  return CanBusAnalysis(library_streams(bus.streams), bus_timing(bus.properties)).results();
}

inline std::string describe(const TestBus& bus) {
  std::ostringstream out;
  out << "bitrate " << bus.properties.bitrate.bits_per_second << ", errors " << bus.properties.errors.max_per_window
      << " per " << bus.properties.errors.window.count() << " ns\n";
  for (const OracleStream& s : bus.streams) {
    out << "  " << (s.format == CanIdFormat::standard11 ? "std 0x" : "ext 0x") << std::hex << s.id << std::dec << " C "
        << s.transmission << " T " << s.period << " J " << s.jitter << "\n";
  }
  return out.str();
}

inline std::string show(const std::optional<Nanos>& r) {
  return r ? std::to_string(r->count()) : std::string("unbounded");
}

inline constexpr std::int64_t kMs = 1'000'000;

}  // namespace cosmic::can_rta_test
