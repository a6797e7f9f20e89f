// The frames of `cosmicctl top`: a pure function of the daemon's last two answers (status,
// segments, channels), so rates are deltas over the time between them. No terminal I/O here.
#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace cosmicctl {

struct TopSample {
  nlohmann::json status;    // answer to {"command":"status"}
  nlohmann::json segments;  // answer to {"command":"segments"}
  nlohmann::json channels;  // answer to {"command":"channels"}
  std::chrono::steady_clock::time_point taken;
};

struct TopLine {
  std::string text;
  bool alert = false;  // a segment not up, a violated channel: drawn in red on a terminal
};

// One frame. `previous` (the sample before, if any) gives the per-second rates; without it the
// rate columns show "-".
std::vector<TopLine> top_frame(const TopSample& current, const std::optional<TopSample>& previous);

}  // namespace cosmicctl
