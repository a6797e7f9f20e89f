// What the Event-Channel Diagram says about each channel beyond its model: offline, what
// admission of the file promises; live, what the running gateway reports (`channels` of the
// control protocol), counters and runtime state included.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/model.hpp"
#include "cosmic/units.hpp"

namespace cosmicctl {

struct ChannelStatus {
  // Admission's verdict ("bound", "degraded", "rejected"), the gateway's ("failed": a transport
  // refused it), or "not bound" for a channel of the file the gateway does not carry.
  std::string verdict = "not bound";
  // Live only: an HRT hop missed its bound recently (runtime_state "violated"). Kept apart from
  // the verdict because the gateway reports both: admitted as bound, then violated at run time.
  bool violated = false;
  std::optional<cosmic::Nanos> end_to_end;     // the promised worst case, publisher to subscriber
  std::optional<cosmic::Nanos> reaction_time;  // what the channel asked for
  std::vector<std::string> counters;           // live: short lines drawn on the channel (forwarded, residence, drops)
  std::vector<std::string> notes;              // the rest: reasons, per-segment counters (tooltip and --detail)
};
using DiagramStatus = std::map<std::string, ChannelStatus>;

// Admission of the file itself, as `cosmicctl check` runs it.
DiagramStatus offline_status(const cosmic::Config& config);

// The `channels` array of the control protocol's answer.
DiagramStatus live_status(const nlohmann::json& channels);

}  // namespace cosmicctl
