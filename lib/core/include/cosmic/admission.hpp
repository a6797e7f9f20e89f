// Admission and QoS-mismatch checks (DESIGN.md section 4) as pure functions.
//
// evaluate() analyses one set of channels as if all of them were bound together: CAN priorities
// (class band, deadline-monotonic inside it), frame times, worst-case response times with a
// holistic jitter iteration across gateway hops, bandwidth, latency budget, validity, omission
// and real-time capability. The incremental policy (a newcomer never breaks an admitted HRT
// channel) lives in KnowledgeBase, which calls evaluate() for each tentative set.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cosmic/model.hpp"

namespace cosmic {

enum class Verdict { bound, degraded, rejected };
enum class HopRole { publisher, subscriber };

const char* to_string(Verdict value);
const char* to_string(HopRole value);

// One criterion's number against its limit. `relation` is how value must compare to limit
// ("<=", "<", ">="); ok says whether it does.
struct Check {
  std::string check;  // frame_fit, utilization, response_time, latency, omission, realtime
  double value = 0;
  double limit = 0;
  std::string unit;  // "s", "B", "ratio", "events", "bool"
  std::string relation;
  bool ok = true;
};

struct CanHopPlan {
  std::uint8_t priority = 0;
  std::uint32_t can_id = 0;  // 29-bit identifier as the gateway sends it
  std::uint16_t etag = 0;
  std::uint32_t frame_bytes = 0;        // data bytes of one frame (FD: padded length)
  std::uint32_t frames_per_event = 1;   // > 1 for fragmented NRT events
  Nanos transmission{0};                // worst-case time of one frame
  Nanos jitter{0};                      // release jitter used in the analysis
  std::optional<Nanos> response_time;   // nullopt: unbounded
};

struct HopReport {
  std::string segment;
  HopRole role = HopRole::publisher;
  std::optional<CanHopPlan> can;
  std::optional<Nanos> latency;  // worst-case latency this hop adds; nullopt: unbounded
  std::vector<Check> checks;
};

struct EndToEnd {
  std::optional<Nanos> latency;  // P hop + gateway residence + S hop, worst pair; nullopt: unbounded
  std::optional<Nanos> reaction_time;
  std::optional<Nanos> temp_validity;
  bool latency_ok = true;
  bool validity_ok = true;
  bool ok() const { return latency_ok && validity_ok; }
};

struct ChannelReport {
  std::string name;
  ChannelClass cls = ChannelClass::nrt;
  Verdict verdict = Verdict::bound;
  std::vector<std::string> reasons;
  std::vector<HopReport> hops;
  EndToEnd end_to_end;
};

struct SegmentLoad {
  std::string name;
  SegmentType type = SegmentType::dds;
  double utilization = 0;
  double max_utilization = 0;
};

struct AdmissionReport {
  std::vector<SegmentLoad> segments;
  std::vector<ChannelReport> channels;  // bound and degraded first in bind order, then rejected
  bool any_rejected() const;
  const ChannelReport* find(const std::string& name) const;
};

// Etag of every channel that touches a CAN segment.
using EtagMap = std::map<std::string, std::uint16_t>;

// Bytes an event occupies on an IP segment beyond its payload (envelope + transport headers):
// used for bandwidth and message-size checks.
inline constexpr std::uint64_t kIpOverheadBytes = 96;

struct Evaluation {
  std::vector<ChannelReport> channels;  // same order as the input
  std::vector<SegmentLoad> segments;    // same order as the segments
};

// Analyses `channels` bound together on `segments`. Channel names must refer to existing
// segments (the configuration layer guarantees it).
Evaluation evaluate(const GatewaySpec& gateway, std::span<const SegmentSpec> segments,
                    std::span<const ChannelSpec> channels, const EtagMap& etags);

}  // namespace cosmic
