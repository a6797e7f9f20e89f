#include "gen_skeleton.hpp"

#include <algorithm>
#include <cstdio>

#include "gen_names.hpp"
#include "gen_struct.hpp"
#include "gen_templates.hpp"

namespace cosmicctl {
namespace {

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
  // Typed channels (gen_struct.hpp): their headers, the decoding and encoding around the handlers.
  std::string type_includes, typed_decls, typed_members, typed_definitions;
  std::map<std::string, std::string> type_headers;  // file name -> content
};

// A typed channel's subscriber: the client's bytes decoded into the channel's struct for
// refresh_CHANNEL(); its logic handler takes the struct.
void add_typed_subscriber(Pieces& p, const cosmic::ChannelSpec& c, const std::string& cls) {
  const std::string id = identifier(c.name);
  const std::string event = type_namespace(c) + "::Event";
  p.handler_decls += "  void refresh_" + id + "(const " + event + "& event);  // " + c.name + ", decoded\n";
  p.typed_decls += "  void receive_" + id + "(std::span<const std::uint8_t> bytes);\n";
  p.typed_members += "  " + event + " " + id + "_event_;  // decoded into again and again: its buffers stay\n";
  p.subscribe += "  subscribe(" + id + "_, &" + cls + "::receive_" + id + ");\n";
  p.typed_definitions +=
      fill(kTypedReceiveTemplate, {{"CLASS", cls}, {"ID", id}, {"CHANNEL", c.name}, {"NS", type_namespace(c)}});
  p.logic_handlers +=
      fill(kLogicTypedHandlerTemplate, {{"CLASS", cls}, {"ID", id}, {"CHANNEL", c.name}, {"EVENT", event}});
}

// A typed channel's publisher: publish_CHANNEL(struct) encodes, beside publish_CHANNEL(bytes).
void add_typed_publisher(Pieces& p, const cosmic::ChannelSpec& c, const std::string& cls) {
  const std::string id = identifier(c.name);
  p.publish_decls += "  // The event encoded (" + type_header_name(c) +
                     "); COSMIC_E_INVALID when it does not encode.\n  int publish_" + id + "(const " +
                     type_namespace(c) + "::Event& event);\n";
  p.typed_definitions +=
      fill(kTypedPublishTemplate, {{"CLASS", cls}, {"ID", id}, {"CHANNEL", c.name}, {"NS", type_namespace(c)}});
}

void add_channel(Pieces& p, const cosmic::ChannelSpec& c, const cosmic::ComponentSpec& component,
                 const std::string& cls, const std::string& model_file) {
  const std::string id = identifier(c.name);
  p.descs += channel_desc(c, component);
  p.all += std::string(p.all.empty() ? "" : ", ") + "&" + id;
  p.members += "  cosmic::client::Channel& " + id + "_;\n";
  p.announce += ",\n      " + id + "_(client_->announce(channels::" + id + "))";
  if (c.type) {
    p.type_includes += "#include \"" + type_header_name(c) + "\"\n";
    p.type_headers[type_header_name(c)] = generate_type_header(c, model_file);
  }
  if (has(component.subscribes, c.name)) {
    if (c.type) {
      add_typed_subscriber(p, c, cls);
    } else {
      p.handler_decls += "  void refresh_" + id + "(std::span<const std::uint8_t> event);  // " + c.name + "\n";
      p.subscribe += "  subscribe(" + id + "_, &" + cls + "::refresh_" + id + ");\n";
      p.logic_handlers += fill(kLogicHandlerTemplate, {{"CLASS", cls}, {"ID", id}, {"CHANNEL", c.name}});
    }
  }
  if (has(component.publishes, c.name)) {
    p.publish_decls +=
        "  int publish_" + id + "(std::span<const std::uint8_t> event) { return " + id + "_.publish(event); }\n";
    if (c.type) add_typed_publisher(p, c, cls);
    if (c.period) {
      p.period_decls += "  void " + id + "_period();  // every " + cosmic::format_duration(*c.period) + "\n";
      p.periods += "      {std::chrono::nanoseconds(" + std::to_string(c.period->count()) + "), &" + cls + "::" + id +
                   "_period},\n";
      p.logic_periods +=
          fill(kLogicPeriodTemplate, {{"CLASS", cls},
                                      {"COMPONENT", component.name},
                                      {"ID", id},
                                      {"CHANNEL", c.name},
                                      {"WHAT", c.type ? "a " + type_namespace(c) + "::Event" : std::string("bytes")},
                                      {"PERIOD", cosmic::format_duration(*c.period)}});
    }
  }
}

// What a component with typed channels has besides: the count of the events refused.
void add_refusals(Pieces& p, const std::string& component, const std::string& cls) {
  if (p.type_headers.empty()) return;
  p.typed_decls += kTypedRefusedDecl;
  p.typed_members += "  std::atomic<std::uint64_t> refused_events_{0};\n";
  p.typed_definitions += fill(kTypedRefusedTemplate, {{"CLASS", cls}, {"COMPONENT", component}});
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

Skeleton generate_skeleton(const cosmic::Config& config, const cosmic::ComponentSpec& component,
                           const std::string& model_file, const std::string& client_config_dir) {
  const std::string cls = camel(component.name);
  const std::string file = identifier(component.name);
  Pieces p;
  for (const auto* c : used_channels(config, component)) add_channel(p, *c, component, cls, model_file);
  add_refusals(p, component.name, cls);
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
      {"CLIENT_SEGMENT", literal_text(cosmic::client_segment(*config.find_segment(component.segment), node))},
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
      {"LOGIC_PERIODS", p.logic_periods},
      {"TYPE_INCLUDES", p.type_includes},
      {"TYPED_DECLS", p.typed_decls},
      {"TYPED_MEMBERS", p.typed_members},
      {"TYPED_DEFINITIONS", p.typed_definitions}};
  Skeleton out;
  out.files["CMakeLists.txt"] = fill(kCMakeTemplate, values);
  out.files["channels.hpp"] = fill(kChannelsTemplate, values);
  out.files[file + ".hpp"] = fill(kHeaderTemplate, values);
  out.files[file + ".cpp"] = fill(kSourceTemplate, values);
  out.files["main.cpp"] = fill(kMainTemplate, values);
  out.logic_file = file + "_logic.cpp";
  out.files[out.logic_file] = fill(kLogicTemplate, values);
  for (const auto& [name, text] : p.type_headers) out.files[name] = text;
  if (!p.type_headers.empty()) out.files["compact.hpp"] = compact_header();
  return out;
}

}  // namespace cosmicctl
