// Builders shared by the unit tests: segments and channels written in a line each, with the
// figures the hand computations in the tests rely on.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "cosmic/admission.hpp"
#include "cosmic/model.hpp"

namespace cosmic::test {

using namespace std::chrono_literals;

inline SegmentSpec can_segment(const std::string& name, std::uint64_t bitrate = 500'000, double max_utilization = 0.7) {
  SegmentSpec s;
  s.name = name;
  s.type = SegmentType::can;
  s.max_utilization = max_utilization;
  s.can.interface = "vcan0";
  s.can.bitrate = BitRate{bitrate};
  s.can.data_bitrate = BitRate{bitrate};
  return s;
}

inline SegmentSpec dds_segment(const std::string& name, Nanos latency_bound = 1ms, bool realtime = true,
                               Reliability reliability = Reliability::reliable) {
  SegmentSpec s;
  s.name = name;
  s.type = SegmentType::dds;
  s.latency_bound = latency_bound;
  s.realtime = realtime;
  s.reliability = reliability;
  return s;
}

inline SegmentSpec lcm_segment(const std::string& name, Nanos latency_bound = 5ms) {
  SegmentSpec s;
  s.name = name;
  s.type = SegmentType::lcm;
  s.latency_bound = latency_bound;
  s.reliability = Reliability::best_effort;
  return s;
}

inline ChannelSpec channel(const std::string& name, std::uint64_t subject, ChannelClass cls,
                           std::vector<std::string> publishers, std::vector<std::string> subscribers,
                           std::uint64_t payload = 8, std::optional<Nanos> period = Nanos(10ms),
                           std::optional<Nanos> reaction_time = Nanos(5ms)) {
  ChannelSpec c;
  c.name = name;
  c.subject = subject;
  c.cls = cls;
  c.payload = payload;
  c.period = period;
  c.reaction_time = cls == ChannelClass::nrt ? std::optional<Nanos>{} : reaction_time;
  c.omission_degree = 1;
  c.publishers = std::move(publishers);
  c.subscribers = std::move(subscribers);
  return c;
}

inline GatewaySpec gateway(Nanos residence = 500us, std::uint8_t node = 1) {
  GatewaySpec g;
  g.name = "test-gw";
  g.can_node_id = node;
  g.residence_bound = residence;
  return g;
}

inline const HopReport* find_hop(const ChannelReport& report, const std::string& segment) {
  for (const auto& h : report.hops) {
    if (h.segment == segment) return &h;
  }
  return nullptr;
}

inline const Check* find_check(const HopReport& hop, const std::string& name) {
  for (const auto& c : hop.checks) {
    if (c.check == name) return &c;
  }
  return nullptr;
}

inline bool has_reason(const ChannelReport& report, const std::string& fragment) {
  for (const auto& r : report.reasons) {
    if (r.find(fragment) != std::string::npos) return true;
  }
  return false;
}

inline std::string reasons_text(const ChannelReport& report) {
  std::string out;
  for (const auto& r : report.reasons) out += r + "\n";
  return out;
}

}  // namespace cosmic::test
