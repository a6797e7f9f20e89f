// Seeded random channel sets for the incremental-admission tests: a few CAN buses (classic and FD,
// with and without a fault hypothesis), a DDS and an LCM segment, and channels of every class with
// periods, reaction times and payloads drawn so that some sets overload a bus, some spread more
// than 16 HRT channels over the HRT band and some chain CAN to CAN (holistic jitter iteration).
// Same seed, same set, on every machine (std::mt19937_64 is fully specified; no std
// distributions, whose output is implementation-defined).
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace cosmic::test {

struct RandomSet {
  GatewaySpec gateway;
  std::vector<SegmentSpec> segments;
  std::vector<ChannelSpec> channels;
};

class RandomSets {
 public:
  explicit RandomSets(std::uint64_t seed) : rng_(seed) {}

  RandomSet next() {
    RandomSet set;
    set.gateway = gateway(Nanos(pick({50'000, 100'000, 500'000})));
    set.segments.push_back(random_can("can0"));
    if (chance(2)) set.segments.push_back(random_can("can1"));
    set.segments.push_back(dds_segment("lan", Nanos(pick({100'000, 1'000'000})), chance(2)));
    set.segments.push_back(lcm_segment("viz"));
    const std::size_t count = 1 + below(chance(3) ? 60 : 24);
    const bool hrt_heavy = chance(3);
    for (std::size_t i = 0; i < count; ++i) set.channels.push_back(random_channel(set.segments, i, hrt_heavy));
    return set;
  }

 private:
  std::uint64_t below(std::uint64_t n) { return rng_() % n; }
  bool chance(std::uint64_t one_in) { return below(one_in) == 0; }
  std::int64_t pick(std::initializer_list<std::int64_t> values) { return values.begin()[below(values.size())]; }

  SegmentSpec random_can(const std::string& name) {
    SegmentSpec s = can_segment(name, static_cast<std::uint64_t>(pick({125'000, 250'000, 500'000, 1'000'000})),
                                chance(4) ? 1.0 : 0.7);
    if (chance(4)) {
      s.can.fd = true;
      s.can.data_bitrate = BitRate{2'000'000};
    } else if (chance(3)) {
      s.can.profile = CanProfile::famouso;  // classic CAN only; its own identifiers and priorities
    }
    if (chance(3))
      s.can.errors =
          CanFaultHypothesis{static_cast<std::uint32_t>(1 + below(2)), Nanos(pick({10'000'000, 100'000'000}))};
    return s;
  }

  ChannelSpec random_channel(const std::vector<SegmentSpec>& segments, std::size_t i, bool hrt_heavy) {
    const auto cls = hrt_heavy && !chance(4) ? ChannelClass::hrt : static_cast<ChannelClass>(below(3));
    const std::string pub = segments[below(segments.size())].name;
    std::string sub = segments[below(segments.size())].name;
    if (sub == pub) sub = pub == "lan" ? "viz" : "lan";
    const std::uint64_t payload = chance(6) ? 9 + below(60) : 1 + below(8);
    std::optional<Nanos> period;
    if (!chance(8)) period = Nanos(pick({2'000'000, 5'000'000, 10'000'000, 20'000'000, 100'000'000, 1'000'000'000}));
    const Nanos reaction(pick({1'000'000, 3'000'000, 5'000'000, 10'000'000, 20'000'000, 50'000'000}));
    // Subjects collide now and then on purpose (deadline ties ordered by subject, duplicates refused).
    ChannelSpec c =
        channel("c" + std::to_string(i), 1 + below(4 * (i + 1)), cls, {pub}, {sub}, payload, period, reaction);
    c.omission_degree = static_cast<std::uint32_t>(below(2));
    if (chance(3)) c.temp_validity = Nanos(pick({5'000'000, 20'000'000, 100'000'000}));
    if (chance(10)) c.etag = static_cast<std::uint16_t>(200 + below(50));
    if (chance(6)) c.subscribers.push_back(segments[below(segments.size())].name == pub ? "viz" : "lan");
    if (c.subscribers.size() == 2 && c.subscribers[0] == c.subscribers[1]) c.subscribers.pop_back();
    return c;
  }

  std::mt19937_64 rng_;
};

}  // namespace cosmic::test
