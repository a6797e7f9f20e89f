// The Event-Channel Diagram (Kaiser et al., Fig. 6) as Graphviz DOT, read left to right:
// publishing components, the channels in the middle tied to them by P tags, then the subscribing
// components tied by S tags. A component that does both is drawn on both sides, so no edge runs
// back across the page. Components sit in a cluster of their segment on each side (a segment
// where a channel has a P/S tag that no modelled component accounts for is a node of its own
// there). Channels are coloured by verdict and read as diagram_labels.hpp says. Pure text
// building; the caller renders it (dot -Tsvg).
#pragma once

#include <string>

#include "cosmic/model.hpp"
#include "diagram_labels.hpp"
#include "diagram_status.hpp"

namespace cosmicctl {

std::string render_dot(const cosmic::Config& config, const DiagramStatus& status, const std::string& title,
                       DiagramDetail detail = DiagramDetail::compact);

}  // namespace cosmicctl
