// The Event-Channel Diagram (Kaiser et al., Fig. 6) as Graphviz DOT: channels in the middle with
// subject, class and QoS list; components (and segments without a modelled component) around
// them, tied to each channel by P (publishes) and S (subscribes) edges; every channel coloured
// by its admission verdict. Pure text building; the caller renders it (dot -Tsvg).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "cosmic/model.hpp"

namespace cosmicctl {

// What the diagram says about one channel beyond its model: the verdict ("bound", "degraded",
// "rejected", "failed", "violated", or "not bound" for a channel the gateway does not carry) and
// extra lines (admission's promise offline; live counters and measured residence from cosmicd).
struct ChannelStatus {
  std::string verdict = "not bound";
  std::vector<std::string> notes;
};
using DiagramStatus = std::map<std::string, ChannelStatus>;

std::string render_dot(const cosmic::Config& config, const DiagramStatus& status, const std::string& title);

// Fill colour of a verdict (also used by the legend).
const char* verdict_colour(const std::string& verdict);

}  // namespace cosmicctl
