// Everything /metrics shows, copied out of the gateway in one go by the control thread (the only
// thread that may call Gateway) and then read, never changed, by the metrics thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/gateway.hpp"
#include "cosmic/recorder.hpp"
#include "federation_member.hpp"

namespace cosmicd {

struct MetricsSnapshot {
  std::string gateway_name;
  std::string gateway_id;  // 16 hex digits
  double uptime_seconds = 0;
  cosmic::Nanos residence_bound{0};
  std::size_t router_queued = 0;
  std::uint64_t router_handled = 0;
  std::vector<cosmic::SegmentInfo> segments;
  std::vector<cosmic::ChannelReport> channels;      // admission's verdicts and numbers
  std::vector<cosmic::ChannelStatsSnapshot> stats;  // the router's counters, by channel name
  FederationSnapshot federation;                    // filled in by the daemon
  std::optional<cosmic::RecorderStatus> recording;  // filled in by the daemon while it has a recorder
};

// Control thread only.
MetricsSnapshot take_metrics_snapshot(const cosmic::Gateway& gateway, std::chrono::steady_clock::time_point started);

}  // namespace cosmicd
