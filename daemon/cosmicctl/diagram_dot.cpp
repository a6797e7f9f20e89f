#include "diagram_dot.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

namespace cosmicctl {
namespace {

// The two sides of the page: publishers left of the channels, subscribers right of them.
enum class Side { publisher, subscriber };

const char* tag(Side side) { return side == Side::publisher ? "P" : "S"; }
const char* role(Side side) { return side == Side::publisher ? "publisher" : "subscriber"; }

// DOT identifiers: the kind's prefix and the name, quoted. Names hold [A-Za-z0-9_.-] only (the
// loader checks), so quoting keeps every name its own node: arm-left and arm.left stay two
// (issue 22, item 5). The side is part of the prefix because a component that publishes and
// subscribes is two nodes, one on each side.
std::string id(const std::string& prefix, const std::string& name) { return "\"" + prefix + name + "\""; }
std::string component_id(Side side, const std::string& name) {
  return id(std::string(tag(side)) + "_component_", name);
}
std::string segment_id(Side side, const std::string& name) { return id(std::string(tag(side)) + "_segment_", name); }
std::string channel_id(const std::string& name) { return id("channel_", name); }

bool lists(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

// SVG class names carry no spaces: "not bound" becomes "not-bound".
std::string css_class(std::string text) {
  std::replace(text.begin(), text.end(), ' ', '-');
  return text;
}

const std::vector<std::string>& channels_of(const cosmic::ComponentSpec& component, Side side) {
  return side == Side::publisher ? component.publishes : component.subscribes;
}

const std::vector<std::string>& segments_of(const cosmic::ChannelSpec& channel, Side side) {
  return side == Side::publisher ? channel.publishers : channel.subscribers;
}

// The model's components with its FMUs among them (an FMU is a component that publishes its output
// channels and subscribes its input channels; docs/fmu.md), in the file's order: components first.
std::vector<cosmic::ComponentSpec> drawn_components(const cosmic::Config& config) {
  std::vector<cosmic::ComponentSpec> out = config.components;
  for (const auto& f : config.fmus) out.push_back({f.name, f.segment, f.publishes(), f.subscribes()});
  return out;
}

class DotWriter {
 public:
  DotWriter(const cosmic::Config& config, const DiagramStatus& status, DiagramDetail detail)
      : config_(config), status_(status), detail_(detail), components_(drawn_components(config)) {}

  std::string write(const std::string& title) {
    out_ << "digraph event_channels {\n"
         << "  rankdir=LR; newrank=true; nodesep=0.12; ranksep=0.9; fontname=\"Helvetica\"; labelloc=t;\n"
         << "  label=" << title_label(title) << ";\n"
         << "  node [fontname=\"Helvetica\", fontsize=10]; edge [fontname=\"Helvetica\", fontsize=10, penwidth=1.2, "
            "arrowsize=0.7];\n";
    for (const auto& s : config_.segments) write_cluster(s, Side::publisher);
    for (const auto& c : config_.channels) write_channel(c);
    for (const auto& s : config_.segments) write_cluster(s, Side::subscriber);
    for (const auto& c : config_.channels) write_edges(c);
    // Fig. 6 as three columns: every publisher, then every channel, then every subscriber.
    write_column(publisher_nodes_);
    write_column(channel_nodes_);
    write_column(subscriber_nodes_);
    out_ << "}\n";
    return out_.str();
  }

 private:
  // The title with the key under it, so the key costs no column of its own.
  static std::string title_label(const std::string& title) {
    std::string label =
        "<<TABLE BORDER=\"0\" CELLSPACING=\"3\" CELLPADDING=\"2\"><TR><TD COLSPAN=\"8\"><FONT POINT-SIZE=\"14\">" +
        html_text(title) + "</FONT></TD></TR><TR><TD>verdict:</TD>";
    for (const char* v : {"bound", "degraded", "rejected", "failed", "violated", "not bound"}) {
      label += std::string("<TD BORDER=\"1\" BGCOLOR=\"") + verdict_colour(v) + "\">" + v + "</TD>";
    }
    return label + "<TD>P publishes, S subscribes; hover over a channel for its QoS and counters</TD></TR></TABLE>>";
  }

  // Whether a modelled component on `segment` accounts for the channel's P (or S) tag there.
  bool covered(const cosmic::ChannelSpec& c, const std::string& segment, Side side) const {
    return std::any_of(components_.begin(), components_.end(), [&](const cosmic::ComponentSpec& component) {
      return component.segment == segment && lists(channels_of(component, side), c.name);
    });
  }

  // The channels with a tag on `segment` that no component accounts for.
  std::vector<std::string> uncovered_channels(const std::string& segment, Side side) const {
    std::vector<std::string> out;
    for (const auto& c : config_.channels) {
      if (lists(segments_of(c, side), segment) && !covered(c, segment, side)) out.push_back(c.name);
    }
    return out;
  }

  // A component is drawn on each side where it has channels; one with none at all still
  // appears, on the publishers' side, so that no modelled component is missing.
  static bool drawn_on(const cosmic::ComponentSpec& component, Side side) {
    if (!channels_of(component, side).empty()) return true;
    return side == Side::publisher && component.subscribes.empty() && component.publishes.empty();
  }

  // One segment's cluster on one side: its components there and, where a channel has a tag on
  // the segment that no component accounts for, the segment itself.
  void write_cluster(const cosmic::SegmentSpec& s, Side side) {
    std::vector<const cosmic::ComponentSpec*> components;
    for (const auto& c : components_) {
      if (c.segment == s.name && drawn_on(c, side)) components.push_back(&c);
    }
    const std::vector<std::string> uncovered = uncovered_channels(s.name, side);
    if (components.empty() && uncovered.empty()) return;
    const std::string segment = s.name + " (" + cosmic::to_string(s.type) + ")";
    const std::string verb = side == Side::publisher ? " publishes " : " subscribes ";
    auto& column = side == Side::publisher ? publisher_nodes_ : subscriber_nodes_;
    out_ << "  subgraph " << id(std::string("cluster_") + tag(side) + "_", s.name) << " {\n    label=\"" << segment
         << "\"; class=\"segment\"; style=\"rounded,filled\"; fillcolor=\"#e3f2fd\"; color=\"#1565c0\"; tooltip="
         << dot_string({"segment " + segment + ": " + role(side) + "s"}) << ";\n";
    for (const auto* c : components) {
      const std::string node = component_id(side, c->name);
      column.push_back(node);
      const cosmic::FmuSpec* fmu = fmu_named(c->name);
      // An FMU: its own fill, "FMU, step" under its name, the model and version in its tooltip.
      const std::string kind = fmu ? "FMU " + fmu->model_identifier + " (FMI " + fmu->fmi_version + "), step " +
                                         cosmic::format_duration(fmu->step) + ", "
                                   : "";
      out_ << "    " << node << " [shape=box, style=\"rounded,filled\", fillcolor=\"" << (fmu ? "#f3e5f5" : "#fff8e1")
           << "\", class=\"" << (fmu ? "component fmu " : "component ") << role(side) << "\", label=\"" << c->name
           << (fmu ? "\\n(FMU, " + cosmic::format_duration(fmu->step) + ")" : "")
           << "\", tooltip=" << dot_string({kind + c->name + " on " + segment + verb + joined(channels_of(*c, side))})
           << "];\n";
    }
    if (!uncovered.empty()) {
      const std::string node = segment_id(side, s.name);
      column.push_back(node);
      out_ << "    " << node << " [shape=cylinder, style=filled, fillcolor=\"#bbdefb\", class=\"segment " << role(side)
           << "\", label=\"" << s.name << "\\n(segment)\", tooltip="
           << dot_string({"segment " + segment + verb + joined(uncovered) + " (no modelled component)"}) << "];\n";
    }
    out_ << "  }\n";
  }

  void write_channel(const cosmic::ChannelSpec& c) {
    const auto found = status_.find(c.name);
    const ChannelStatus status = found == status_.end() ? ChannelStatus{} : found->second;
    const std::string node = channel_id(c.name);
    channel_nodes_.push_back(node);
    out_ << "  " << node << " [shape=plain, class=\"channel "
         << css_class(status.violated ? "violated" : status.verdict)
         << "\", tooltip=" << dot_string(channel_tooltip(c, status)) << ", label=" << channel_label(c, status, detail_)
         << "];\n";
  }

  // P tags at the channel's end of the edges that come in, S tags at the channel's end of those
  // that leave, as in Fig. 6: the tags sit around the channel, not halfway along the edges.
  void write_edges(const cosmic::ChannelSpec& c) {
    const std::string node = channel_id(c.name);
    for (const auto& component : components_) {
      if (lists(component.publishes, c.name)) {
        edge(component_id(Side::publisher, component.name), node, Side::publisher,
             component.name + " publishes " + c.name + " on " + component.segment);
      }
    }
    for (const auto& s : c.publishers) {
      if (!covered(c, s, Side::publisher))
        edge(segment_id(Side::publisher, s), node, Side::publisher, c.name + " is published on " + s);
    }
    for (const auto& component : components_) {
      if (lists(component.subscribes, c.name)) {
        edge(node, component_id(Side::subscriber, component.name), Side::subscriber,
             component.name + " subscribes " + c.name + " on " + component.segment);
      }
    }
    for (const auto& s : c.subscribers) {
      if (!covered(c, s, Side::subscriber))
        edge(node, segment_id(Side::subscriber, s), Side::subscriber, c.name + " is delivered on " + s);
    }
  }

  void edge(const std::string& from, const std::string& to, Side side, const std::string& tooltip) {
    const bool publish = side == Side::publisher;
    const char* colour = publish ? "#2e7d32" : "#1565c0";
    out_ << "  " << from << " -> " << to << " [" << (publish ? "headlabel" : "taillabel") << "=\"" << tag(side)
         << "\", class=\"" << (publish ? "publish" : "subscribe") << "\", color=\"" << colour << "\", fontcolor=\""
         << colour << "\", labeldistance=1.4, tooltip=" << dot_string({tooltip}) << "];\n";
  }

  void write_column(const std::vector<std::string>& nodes) {
    if (nodes.empty()) return;
    out_ << "  { rank=same;";
    for (const auto& node : nodes) out_ << " " << node << ";";
    out_ << " }\n";
  }

  const cosmic::FmuSpec* fmu_named(const std::string& name) const {
    const auto it =
        std::find_if(config_.fmus.begin(), config_.fmus.end(), [&](const auto& f) { return f.name == name; });
    return it == config_.fmus.end() ? nullptr : &*it;
  }

  const cosmic::Config& config_;
  const DiagramStatus& status_;
  const DiagramDetail detail_;
  const std::vector<cosmic::ComponentSpec> components_;
  std::vector<std::string> publisher_nodes_;
  std::vector<std::string> channel_nodes_;
  std::vector<std::string> subscriber_nodes_;
  std::ostringstream out_;
};

}  // namespace

std::string render_dot(const cosmic::Config& config, const DiagramStatus& status, const std::string& title,
                       DiagramDetail detail) {
  return DotWriter(config, status, detail).write(title);
}

}  // namespace cosmicctl
