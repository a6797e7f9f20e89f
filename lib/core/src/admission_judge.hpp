// The verdict of one channel from its hops' latencies and CAN plans and the segment loads: each
// criterion's check and the reasons in numbers (DESIGN.md section 4). Internal to libcosmic's core.
#pragma once

#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "cosmic/admission.hpp"

namespace cosmic::admission_detail {

// The segment named `name` (the configuration layer guarantees it exists).
inline const SegmentSpec& segment_named(std::span<const SegmentSpec> segments, const std::string& name) {
  return *std::find_if(segments.begin(), segments.end(), [&](const auto& s) { return s.name == name; });
}

class Judge {
 public:
  // `loads` by segment, in the order of `segments`; all three must outlive the Judge.
  Judge(const GatewaySpec& gateway, std::span<const SegmentSpec> segments, const std::vector<double>& loads)
      : gateway_(gateway), segments_(segments), loads_(loads) {}

  // Adds the checks of every hop of `report` (whose hops carry their latencies and CAN plans),
  // the end-to-end figures, and the verdict with its reasons.
  void judge(const ChannelSpec& channel, ChannelReport& report) const;

 private:
  void add_hop_checks(const ChannelSpec& channel, const SegmentSpec& segment, HopReport& h) const;
  std::optional<Nanos> end_to_end_latency(const ChannelReport& report) const;

  const GatewaySpec& gateway_;
  std::span<const SegmentSpec> segments_;
  const std::vector<double>& loads_;
};

}  // namespace cosmic::admission_detail
