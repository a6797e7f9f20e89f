#include "gen_skeleton.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "gen_templates.hpp"

namespace cosmicctl {
namespace {

// A C++ identifier from a model name ([A-Za-z0-9_.-]).
std::string identifier(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "c_" + out;
  return out;
}

std::string camel(const std::string& name) {
  std::string out;
  bool up = true;
  for (char c : identifier(name)) {
    if (c == '_') {
      up = true;
      continue;
    }
    out += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    up = false;
  }
  return out.empty() ? "Component" : out;
}

// Text for a `//` or `#` comment: control characters (a newline would end the comment and let the
// rest become code) shown as '?'.
std::string comment_text(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return out;
}

// The body of a C++ string literal: '\\' and '"' escaped, anything not printable ASCII as a
// three-digit octal escape (a hex escape would swallow the hex digits after it).
std::string literal_text(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (byte < 0x20 || byte >= 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\%03o", static_cast<unsigned>(byte));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out;
}

// Every {{KEY}} of `text` replaced by its value.
std::string fill(std::string text, const std::map<std::string, std::string>& values) {
  for (const auto& [key, value] : values) {
    const std::string mark = "{{" + key + "}}";
    for (auto at = text.find(mark); at != std::string::npos; at = text.find(mark, at + value.size()))
      text.replace(at, mark.size(), value);
  }
  return text;
}

std::string ns(const std::optional<cosmic::Nanos>& d) { return d ? std::to_string(d->count()) : "0"; }

const char* class_constant(cosmic::ChannelClass c) {
  switch (c) {
    case cosmic::ChannelClass::hrt:
      return "COSMIC_HRT";
    case cosmic::ChannelClass::srt:
      return "COSMIC_SRT";
    case cosmic::ChannelClass::nrt:
      return "COSMIC_NRT";
  }
  return "COSMIC_NRT";
}

bool has(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

std::string roles(const cosmic::ComponentSpec& c, const std::string& channel) {
  const bool p = has(c.publishes, channel);
  const bool s = has(c.subscribes, channel);
  return p && s ? "COSMIC_PUBLISH | COSMIC_SUBSCRIBE" : p ? "COSMIC_PUBLISH" : "COSMIC_SUBSCRIBE";
}

std::string channel_desc(const cosmic::ChannelSpec& c, const cosmic::ComponentSpec& component) {
  char subject[24];
  std::snprintf(subject, sizeof subject, "0x%016llxull", static_cast<unsigned long long>(c.subject));
  return "// " + c.name + ": " + cosmic::to_string(c.cls) + ", P " + std::to_string(c.publishers.size()) +
         " segment(s), S " + std::to_string(c.subscribers.size()) + " segment(s)\ninline const cosmic_channel_desc " +
         identifier(c.name) + "{\"" + c.name + "\", " + subject + ", " + class_constant(c.cls) + ", " + ns(c.period) +
         ", " + ns(c.reaction_time) + ", " + ns(c.temp_validity) + ", " + std::to_string(c.omission_degree) + ", " +
         std::to_string(c.payload) + ", " + roles(component, c.name) + "};\n";
}

// The channels this component uses, in the model's channel order.
std::vector<const cosmic::ChannelSpec*> used_channels(const cosmic::Config& config, const cosmic::ComponentSpec& c) {
  std::vector<const cosmic::ChannelSpec*> out;
  for (const auto& channel : config.channels) {
    if (has(c.publishes, channel.name) || has(c.subscribes, channel.name)) out.push_back(&channel);
  }
  return out;
}

struct Pieces {
  std::string descs, all, members, handler_decls, period_decls, publish_decls, announce, subscribe, periods,
      logic_handlers, logic_periods;
};

void add_channel(Pieces& p, const cosmic::ChannelSpec& c, const cosmic::ComponentSpec& component,
                 const std::string& cls) {
  const std::string id = identifier(c.name);
  p.descs += channel_desc(c, component);
  p.all += std::string(p.all.empty() ? "" : ", ") + "&" + id;
  p.members += "  cosmic::client::Channel& " + id + "_;\n";
  p.announce += ",\n      " + id + "_(client_->announce(channels::" + id + "))";
  if (has(component.subscribes, c.name)) {
    p.handler_decls += "  void refresh_" + id + "(std::span<const std::uint8_t> event);  // " + c.name + "\n";
    p.subscribe += "  subscribe(" + id + "_, &" + cls + "::refresh_" + id + ");\n";
    p.logic_handlers += fill(kLogicHandlerTemplate, {{"CLASS", cls}, {"ID", id}, {"CHANNEL", c.name}});
  }
  if (has(component.publishes, c.name)) {
    p.publish_decls +=
        "  int publish_" + id + "(std::span<const std::uint8_t> event) { return " + id + "_.publish(event); }\n";
    if (c.period) {
      p.period_decls += "  void " + id + "_period();  // every " + cosmic::format_duration(*c.period) + "\n";
      p.periods += "      {std::chrono::nanoseconds(" + std::to_string(c.period->count()) + "), &" + cls + "::" + id +
                   "_period},\n";
      p.logic_periods += fill(kLogicPeriodTemplate, {{"CLASS", cls},
                                                     {"COMPONENT", component.name},
                                                     {"ID", id},
                                                     {"CHANNEL", c.name},
                                                     {"PERIOD", cosmic::format_duration(*c.period)}});
    }
  }
}

}  // namespace

cosmic::Result<void> check_identifiers(const cosmic::Config& config, const cosmic::ComponentSpec& component) {
  std::map<std::string, std::string> owner;  // identifier -> channel name
  for (const cosmic::ChannelSpec* c : used_channels(config, component)) {
    const auto [it, fresh] = owner.emplace(identifier(c->name), c->name);
    if (!fresh && it->second != c->name) {
      return cosmic::Error{"channels '" + it->second + "' and '" + c->name + "' of component " + component.name +
                           " both become the C++ identifier " + it->first + "; rename one of them"};
    }
  }
  return {};
}

std::string client_segment(const cosmic::SegmentSpec& s, unsigned can_node) {
  switch (s.type) {
    case cosmic::SegmentType::dds:
      return "dds:" + std::to_string(s.dds.domain) +
             (s.reliability == cosmic::Reliability::best_effort ? "?reliability=best_effort" : "");
    case cosmic::SegmentType::lcm:
      return "lcm:" + s.lcm.url;
    case cosmic::SegmentType::can:
      return "can:" + s.can.interface + "?node=" + std::to_string(can_node);
  }
  return "";
}

Skeleton generate_skeleton(const cosmic::Config& config, const cosmic::ComponentSpec& component,
                           const std::string& model_file, const std::string& client_config_dir) {
  const std::string cls = camel(component.name);
  const std::string file = identifier(component.name);
  Pieces p;
  for (const auto* c : used_channels(config, component)) add_channel(p, *c, component, cls);
  // A CAN component needs a TxNode of its own: one after the gateway's, by component position.
  const auto position = static_cast<unsigned>(&component - config.components.data());
  const unsigned node = (config.gateway.can_node_id + 1 + position) % 128;
  const std::map<std::string, std::string> values{
      {"COMPONENT", component.name},
      {"CLASS", cls},
      {"FILE", file},
      // Everything from outside the model's name grammar is escaped for where it lands (issue 22,
      // item 4): the model's path goes into comments, the segment string into a literal.
      {"MODEL", comment_text(model_file)},
      {"SEGMENT", component.segment},
      {"CLIENT_SEGMENT", literal_text(client_segment(*config.find_segment(component.segment), node))},
      {"CLIENT_CONFIG_DIR", client_config_dir},
      {"DESCS", p.descs},
      {"ALL", p.all},
      {"MEMBERS", p.members},
      {"HANDLER_DECLS", p.handler_decls},
      {"PERIOD_DECLS", p.period_decls},
      {"PUBLISH_DECLS", p.publish_decls},
      {"ANNOUNCE", p.announce},
      {"SUBSCRIBE", p.subscribe},
      {"PERIODS", p.periods},
      {"LOGIC_HANDLERS", p.logic_handlers},
      {"LOGIC_PERIODS", p.logic_periods}};
  Skeleton out;
  out.files["CMakeLists.txt"] = fill(kCMakeTemplate, values);
  out.files["channels.hpp"] = fill(kChannelsTemplate, values);
  out.files[file + ".hpp"] = fill(kHeaderTemplate, values);
  out.files[file + ".cpp"] = fill(kSourceTemplate, values);
  out.files["main.cpp"] = fill(kMainTemplate, values);
  out.logic_file = file + "_logic.cpp";
  out.files[out.logic_file] = fill(kLogicTemplate, values);
  return out;
}

}  // namespace cosmicctl
