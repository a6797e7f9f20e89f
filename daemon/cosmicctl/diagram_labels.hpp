// How a channel reads in the Event-Channel Diagram: its label (compact by default: name, class,
// verdict, end-to-end bound and, live, the counters; or the paper's Fig. 7 table with --detail)
// and its tooltip (everything, for a reader hovering over it in a browser); and the text
// escaping both need so that any name, reason or file path keeps the DOT well formed.
#pragma once

#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "diagram_status.hpp"

namespace cosmicctl {

enum class DiagramDetail {
  compact,  // one row per channel; the QoS list and the notes in its tooltip
  tables,   // the whole QoS list and every note as rows of the channel's table (--detail)
};

// Text inside a Graphviz HTML-like label (an XML parser reads it): &, <, >, " as entities.
std::string html_text(const std::string& text);
// A DOT quoted string ("..." included) whose lines are joined by Graphviz's \n, for tooltips.
std::string dot_string(const std::vector<std::string>& lines);

// Fill colour of a verdict, "violated" included (also used by the legend).
const char* verdict_colour(const std::string& verdict);

// The channel node's HTML-like label, <...> included.
std::string channel_label(const cosmic::ChannelSpec& channel, const ChannelStatus& status, DiagramDetail detail);
// Every line the diagram knows about the channel.
std::vector<std::string> channel_tooltip(const cosmic::ChannelSpec& channel, const ChannelStatus& status);

}  // namespace cosmicctl
