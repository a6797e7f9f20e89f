#include "diagram_dot.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <sstream>

#include "cosmic/units.hpp"

namespace cosmicctl {
namespace {

// Text inside Graphviz HTML-like labels (an XML parser reads them): &, <, >, " as entities,
// control characters and bytes that are not UTF-8 as U+FFFD, so any title or name (a file path
// holds anything) keeps the DOT well formed for every model (issue 22, item 6).
std::string escape(const std::string& text) {
  static const std::string kReplacement = "\xEF\xBF\xBD";
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    if (c == '&' || c == '<' || c == '>' || c == '"') {
      ++i;
      continue;
    }
    if (c < 0x80) {
      out += c < 0x20 || c == 0x7f ? kReplacement : std::string(1, static_cast<char>(c));
      ++i;
      continue;
    }
    // A well-formed UTF-8 sequence (no overlong forms, no surrogates, at most U+10FFFF) is kept.
    const std::size_t length = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
    bool valid = length != 0 && c <= 0xF4 && i + length <= text.size();
    for (std::size_t k = 1; valid && k < length; ++k) valid = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (valid && length >= 3) {
      const auto second = static_cast<unsigned char>(text[i + 1]);
      if ((c == 0xE0 && second < 0xA0) || (c == 0xED && second >= 0xA0) || (c == 0xF0 && second < 0x90) ||
          (c == 0xF4 && second >= 0x90)) {
        valid = false;
      }
    }
    out += valid ? text.substr(i, length) : kReplacement;
    i += valid ? length : 1;
  }
  return out;
}

// DOT identifiers: the kind's prefix and the name, quoted. Names hold [A-Za-z0-9_.-] only (the
// loader checks), so quoting keeps every name its own node: arm-left and arm.left stay two
// (issue 22, item 5), where mapping '-' and '.' to '_' made them one.
std::string id(const std::string& prefix, const std::string& name) { return "\"" + prefix + name + "\""; }

std::string hex_subject(std::uint64_t subject) {
  char buffer[24];
  std::snprintf(buffer, sizeof buffer, "0x%016llx", static_cast<unsigned long long>(subject));
  return buffer;
}

std::string upper(const char* text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return out;
}

// The channel's QoS list as in the paper's Fig. 7.
std::vector<std::string> qos_list(const cosmic::ChannelSpec& c) {
  std::vector<std::string> out;
  if (c.period) out.push_back("period " + cosmic::format_duration(*c.period));
  if (c.reaction_time) out.push_back("reaction_time " + cosmic::format_duration(*c.reaction_time));
  out.push_back("omission_degree " + std::to_string(c.omission_degree));
  if (c.temp_validity) out.push_back("temp_validity " + cosmic::format_duration(*c.temp_validity));
  out.push_back("payload " + std::to_string(c.payload) + " B");
  return out;
}

std::string row(const std::string& text, const char* attributes = "") {
  return std::string("<TR><TD") + attributes + ">" + escape(text) + "</TD></TR>";
}

std::string channel_label(const cosmic::ChannelSpec& c, const ChannelStatus& status) {
  std::string label = "<<TABLE BORDER=\"0\" CELLBORDER=\"1\" CELLSPACING=\"0\" CELLPADDING=\"3\">";
  label += "<TR><TD BGCOLOR=\"#37474f\"><FONT COLOR=\"white\"><B>" + escape(c.name) + "</B></FONT></TD></TR>";
  label += row("subject " + hex_subject(c.subject));
  label += row(upper(cosmic::to_string(c.cls)));
  for (const auto& q : qos_list(c)) label += row(q);
  std::string verdict_attr = std::string(" BGCOLOR=\"") + verdict_colour(status.verdict) + "\"";
  label += row(status.verdict, verdict_attr.c_str());
  for (const auto& note : status.notes) label += row(note, verdict_attr.c_str());
  return label + "</TABLE>>";
}

bool lists(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

class DotWriter {
 public:
  DotWriter(const cosmic::Config& config, const DiagramStatus& status) : config_(config), status_(status) {}

  std::string write(const std::string& title) {
    out_ << "digraph event_channels {\n  rankdir=LR; newrank=true; nodesep=0.25; ranksep=1.2; fontname=\"Helvetica\";\n"
         << "  label=<" << escape(title) << ">; labelloc=t;\n"
         << "  node [fontname=\"Helvetica\", fontsize=10]; edge [fontname=\"Helvetica\", fontsize=10, penwidth=1.4];\n";
    for (const auto& s : config_.segments) write_segment(s);
    for (const auto& c : config_.channels) write_channel(c);
    // Fig. 6: every channel in one middle column, publishers before it, subscribers after it.
    out_ << "  { rank=same;";
    for (const auto& c : config_.channels) out_ << " " << id("channel_", c.name) << ";";
    out_ << " }\n";
    write_legend();
    out_ << "}\n";
    return out_.str();
  }

 private:
  // A segment is a cluster holding its components, plus a node of its own where a channel has
  // a P/S tag on it that no modelled component accounts for.
  void write_segment(const cosmic::SegmentSpec& s) {
    out_ << "  subgraph " << id("cluster_", s.name) << " {\n    label=\"" << s.name << " (" << cosmic::to_string(s.type)
         << ")\"; style=\"rounded,filled\"; fillcolor=\"#e3f2fd\"; color=\"#1565c0\";\n";
    for (const auto& c : config_.components) {
      if (c.segment == s.name) {
        out_ << "    " << id("component_", c.name) << " [shape=box, style=\"rounded,filled\", fillcolor=\"#fff8e1\", label=\""
             << c.name << "\"];\n";
      }
    }
    if (segment_needs_node(s.name)) {
      out_ << "    " << id("segment_", s.name) << " [shape=cylinder, style=filled, fillcolor=\"#bbdefb\", label=\"" << s.name
           << "\\n(segment)\"];\n";
    }
    out_ << "  }\n";
  }

  bool covered(const cosmic::ChannelSpec& c, const std::string& segment, bool publisher) const {
    for (const auto& component : config_.components) {
      if (component.segment == segment && lists(publisher ? component.publishes : component.subscribes, c.name)) return true;
    }
    return false;
  }

  bool segment_needs_node(const std::string& segment) const {
    for (const auto& c : config_.channels) {
      if (lists(c.publishers, segment) && !covered(c, segment, true)) return true;
      if (lists(c.subscribers, segment) && !covered(c, segment, false)) return true;
    }
    return false;
  }

  void write_channel(const cosmic::ChannelSpec& c) {
    const auto found = status_.find(c.name);
    const ChannelStatus status = found == status_.end() ? ChannelStatus{} : found->second;
    const std::string node = id("channel_", c.name);
    out_ << "  " << node << " [shape=plain, label=" << channel_label(c, status) << "];\n";
    for (const auto& component : config_.components) {
      if (lists(component.publishes, c.name)) edge(id("component_", component.name), node, "P");
      if (lists(component.subscribes, c.name)) edge(node, id("component_", component.name), "S");
    }
    for (const auto& s : c.publishers) {
      if (!covered(c, s, true)) edge(id("segment_", s), node, "P");
    }
    for (const auto& s : c.subscribers) {
      if (!covered(c, s, false)) edge(node, id("segment_", s), "S");
    }
  }

  void edge(const std::string& from, const std::string& to, const char* tag) {
    const char* colour = tag[0] == 'P' ? "#2e7d32" : "#1565c0";
    out_ << "  " << from << " -> " << to << " [label=\"" << tag << "\", color=\"" << colour << "\", fontcolor=\"" << colour << "\"];\n";
  }

  void write_legend() {
    out_ << "  legend [shape=plain, label=<<TABLE BORDER=\"0\" CELLBORDER=\"1\" CELLSPACING=\"0\" CELLPADDING=\"3\">"
         << "<TR><TD>verdict</TD></TR>";
    for (const char* v : {"bound", "degraded", "rejected", "failed", "violated", "not bound"}) {
      out_ << "<TR><TD BGCOLOR=\"" << verdict_colour(v) << "\">" << v << "</TD></TR>";
    }
    out_ << "</TABLE>>];\n";
  }

  const cosmic::Config& config_;
  const DiagramStatus& status_;
  std::ostringstream out_;
};

}  // namespace

const char* verdict_colour(const std::string& verdict) {
  if (verdict == "bound") return "#a5d6a7";
  if (verdict == "degraded") return "#ffe082";
  if (verdict == "rejected") return "#ef9a9a";
  if (verdict == "failed") return "#e57373";  // admitted, refused by its transport
  if (verdict == "violated") return "#ffab91";
  return "#e0e0e0";
}

std::string render_dot(const cosmic::Config& config, const DiagramStatus& status, const std::string& title) {
  return DotWriter(config, status).write(title);
}

}  // namespace cosmicctl
