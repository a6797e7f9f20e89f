#include "diagram_labels.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "cosmic/units.hpp"

namespace cosmicctl {
namespace {

// Control characters and bytes that are not UTF-8 become U+FFFD, so any title, name, reason or
// the gateway's own text (a file path holds anything) keeps the DOT well formed for every model
// (issue 22, item 6).
std::string clean_utf8(const std::string& text) {
  static const std::string kReplacement = "\xEF\xBF\xBD";
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
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

std::string hex_subject(std::uint64_t subject) {
  char buffer[24];
  std::snprintf(buffer, sizeof buffer, "0x%016llx", static_cast<unsigned long long>(subject));
  return buffer;
}

std::string upper(const char* text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return out;
}

std::string joined(const std::vector<std::string>& items, const char* separator) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : separator) + item;
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

// What the reader looks for first: the verdict, or at run time that the channel missed its bound.
std::string shown_verdict(const ChannelStatus& status) { return status.violated ? "violated" : status.verdict; }

std::string end_to_end_text(const ChannelStatus& status) {
  if (!status.end_to_end) return status.verdict == "not bound" ? "" : "end-to-end unbounded";
  std::string text = "end-to-end \u2264 " + cosmic::format_duration(*status.end_to_end);
  if (status.reaction_time) text += " (reaction " + cosmic::format_duration(*status.reaction_time) + ")";
  return text;
}

std::string cell(const std::string& text, const std::string& attributes = "") {
  return "<TD" + attributes + ">" + html_text(text) + "</TD>";
}

std::string background_attribute(const char* colour) { return std::string(" BGCOLOR=\"") + colour + "\""; }

// A violated channel's table gets a thick red frame, so it stands out among fifty at a glance.
std::string table_open(const ChannelStatus& status) {
  return std::string("<TABLE BORDER=\"") + (status.violated ? "3\" COLOR=\"#c62828\"" : "0\"") +
         " CELLBORDER=\"1\" CELLSPACING=\"0\" CELLPADDING=\"3\">";
}

std::string name_cell(const cosmic::ChannelSpec& c) {
  return "<TD BGCOLOR=\"#37474f\"><FONT COLOR=\"white\"><B>" + html_text(c.name) + "</B></FONT></TD>";
}

std::string verdict_cell(const ChannelStatus& status) {
  const std::string verdict = shown_verdict(status);
  const std::string text = status.violated ? "<B>VIOLATED</B>" : html_text(verdict);
  return std::string("<TD") + background_attribute(verdict_colour(verdict)) + ">" + text + "</TD>";
}

// One row: name, class, verdict, the bound (its number only: the tooltip says what it is) and,
// live, the counters.
std::string compact_label(const cosmic::ChannelSpec& c, const ChannelStatus& status) {
  std::string label =
      "<" + table_open(status) + "<TR>" + name_cell(c) + cell(upper(cosmic::to_string(c.cls))) + verdict_cell(status);
  if (status.end_to_end) label += "<TD>&#8804; " + html_text(cosmic::format_duration(*status.end_to_end)) + "</TD>";
  if (!status.counters.empty()) label += cell(joined(status.counters, ", "));
  return label + "</TR></TABLE>>";
}

// The paper's Fig. 7 for the channel: subject, class, QoS list, then the verdict and every note.
std::string table_label(const cosmic::ChannelSpec& c, const ChannelStatus& status) {
  const auto row = [](const std::string& content) { return "<TR>" + content + "</TR>"; };
  std::string label = "<" + table_open(status) + row(name_cell(c));
  label += row(cell("subject " + hex_subject(c.subject)));
  label += row(cell(upper(cosmic::to_string(c.cls))));
  for (const auto& q : qos_list(c)) label += row(cell(q));
  label += row(verdict_cell(status));
  const std::string verdict_fill = background_attribute(verdict_colour(shown_verdict(status)));
  if (const std::string bound = end_to_end_text(status); !bound.empty()) label += row(cell(bound, verdict_fill));
  for (const auto& line : status.counters) label += row(cell(line, verdict_fill));
  for (const auto& note : status.notes) label += row(cell(note, verdict_fill));
  return label + "</TABLE>>";
}

}  // namespace

std::string html_text(const std::string& text) {
  std::string out;
  for (const char c : clean_utf8(text)) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

// Graphviz expands backslash sequences in these strings (\N is the node's name), so a backslash
// of the text is doubled; the lines are joined by \n, which Graphviz turns into a line break.
std::string dot_string(const std::vector<std::string>& lines) {
  std::string out = "\"";
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (i > 0) out += "\\n";
    for (const char c : clean_utf8(lines[i])) {
      if (c == '\\' || c == '"') out += '\\';
      out += c;
    }
  }
  return out + "\"";
}

const char* verdict_colour(const std::string& verdict) {
  if (verdict == "bound") return "#a5d6a7";
  if (verdict == "degraded") return "#ffe082";
  if (verdict == "rejected") return "#ef9a9a";
  if (verdict == "failed") return "#e57373";  // admitted, refused by its transport
  if (verdict == "violated") return "#ffab91";
  return "#e0e0e0";
}

std::string channel_label(const cosmic::ChannelSpec& channel, const ChannelStatus& status, DiagramDetail detail) {
  return detail == DiagramDetail::tables ? table_label(channel, status) : compact_label(channel, status);
}

std::vector<std::string> channel_tooltip(const cosmic::ChannelSpec& c, const ChannelStatus& status) {
  std::vector<std::string> lines{
      c.name + ": " + upper(cosmic::to_string(c.cls)) + ", subject " + hex_subject(c.subject),
      joined(qos_list(c), ", ")};
  std::string verdict = "verdict " + status.verdict;
  if (status.violated) verdict += ", VIOLATED at run time";
  if (const std::string bound = end_to_end_text(status); !bound.empty()) verdict += "; " + bound;
  lines.push_back(verdict);
  lines.push_back("P: " + joined(c.publishers, ", ") + "; S: " + joined(c.subscribers, ", "));
  lines.insert(lines.end(), status.counters.begin(), status.counters.end());
  lines.insert(lines.end(), status.notes.begin(), status.notes.end());
  return lines;
}

}  // namespace cosmicctl
