#include "native_loader.hpp"

#include <algorithm>

#include "cosmic/can_background.hpp"
#include "cosmic/can_wire.hpp"
#include "cosmic/dds_names.hpp"
#include "cosmic/transport_limits.hpp"
#include "type_file_loader.hpp"

namespace cosmic::config_detail {
namespace {

// `representation:` of a typed channel's CAN or LCM hop: the first choice is the type source's own
// form (dbc, lcm), then compact, then json.
bool parse_form(YamlReader& reader, const YAML::Node& node, const std::string& path,
                std::initializer_list<const char*> choices, NativeBinding& binding) {
  if (!node["representation"]) return true;
  const auto choice = reader.choice(node["representation"], key(path, "representation"), choices);
  if (!choice) return false;
  binding.form = *choice == 0 ? NativeForm::source : *choice == 1 ? NativeForm::compact : NativeForm::json;
  return true;
}

bool check_can_frame(YamlReader& reader, const YAML::Node& node, const std::string& path, const SegmentSpec& segment,
                     const NativeCanFrame& frame, NativeBinding& binding);

// `map: {FIELD: SIGNAL}`: which signal carries a field, where the names differ.
std::optional<std::map<std::string, std::string>> parse_field_map(YamlReader& reader, const YAML::Node& node,
                                                                  const std::string& path) {
  if (!node.IsMap()) {
    reader.error_at(node, path, "expected a map of the channel's fields to the message's signals",
                    "map: {Speed: VehicleSpeed}");
    return std::nullopt;
  }
  std::map<std::string, std::string> map;
  for (const auto& entry : node) {
    const auto signal = reader.string(entry.second, key(path, entry.first.Scalar()));
    if (!signal) return std::nullopt;
    map[entry.first.Scalar()] = *signal;
  }
  return map;
}

// `native: {BUS: {dbc: FILE, message: NAME, map: {...}, omit: [...], e2e: {...}}}`: the signal gateway's frame,
// its identifier the message's (a can_id given must be it).
bool parse_can_message(YamlReader& reader, const YAML::Node& node, const std::string& path,
                       std::vector<std::string>& included, NativeCanFrame& frame) {
  if (!node["message"]) {
    reader.error_at(node, key(path, "message"), "missing required key 'message'",
                    "the DBC message the frame is, e.g. message: VehicleSpeed");
    return false;
  }
  const auto file = reader.string(node["dbc"], key(path, "dbc"));
  const auto name = reader.string(node["message"], key(path, "message"));
  if (!file || !name) return false;
  const auto loaded = load_dbc_file(reader, node["dbc"], key(path, "dbc"), *file, included);
  if (!loaded) return false;
  const auto& messages = loaded->file.messages;
  const auto message =
      std::find_if(messages.begin(), messages.end(), [&](const DbcMessage& m) { return m.name == *name; });
  if (message == messages.end()) {
    reader.error_at(node["message"], key(path, "message"), "no message " + quote_value(*name) + " in " + loaded->path);
    return false;
  }
  frame.dbc_message = *message;
  frame.dbc_file = loaded->path;
  frame.can_id = message->can_id;
  frame.extended = message->extended;
  if (node["map"]) {
    auto map = parse_field_map(reader, node["map"], key(path, "map"));
    if (!map) return false;
    frame.field_map = std::move(*map);
  }
  if (node["omit"]) {
    auto omitted = reader.string_list(node["omit"], key(path, "omit"));
    if (!omitted) return false;
    frame.omitted_fields = std::move(*omitted);
  }
  if (node["e2e"]) {
    frame.e2e = parse_e2e(reader, node["e2e"], key(path, "e2e"), *message);
    if (!frame.e2e) return false;
  }
  if (node["can_id"]) {
    const auto id = reader.unsigned_int(node["can_id"], key(path, "can_id"), 0, kExtendedIdMax);
    if (!id) return false;
    if (*id != frame.can_id) {
      reader.error_at(node["can_id"], key(path, "can_id"),
                      can_id_text(static_cast<std::uint32_t>(*id), frame.extended) + " is not message " +
                          message->name + "'s identifier " + can_id_text(frame.can_id, frame.extended),
                      "leave out can_id: the message gives it");
      return false;
    }
  }
  if (node["extended"] || node["representation"]) {
    const char* which = node["extended"] ? "extended" : "representation";
    reader.error_at(node[which], key(path, which), std::string(which) + " comes from the DBC message",
                    "leave it out beside dbc and message");
    return false;
  }
  return true;
}

bool parse_can(YamlReader& reader, const YAML::Node& node, const std::string& path, const SegmentSpec& segment,
               std::vector<std::string>& included, NativeBinding& binding) {
  if (!reader.check_map(node, path, {"can_id", "extended", "representation", "dbc", "message", "map", "omit", "e2e"}))
    return false;
  NativeCanFrame frame;
  if (node["dbc"]) {
    if (!parse_can_message(reader, node, path, included, frame)) return false;
    return check_can_frame(reader, node, path, segment, frame, binding);
  }
  for (const char* only : {"message", "map", "omit", "e2e"}) {
    if (node[only]) {
      reader.error_at(
          node[only], key(path, only), std::string(only) + " belongs to a frame given as a DBC message",
          "dbc: FILE, message: NAME beside it (the signal gateway), or the channel's type: {dbc, message, e2e}");
      return false;
    }
  }
  if (!parse_form(reader, node, path, {"dbc", "compact"}, binding)) return false;
  if (node["extended"]) {
    const auto extended = reader.boolean(node["extended"], key(path, "extended"));
    if (!extended) return false;
    frame.extended = *extended;
  }
  if (!node["can_id"]) {
    reader.error_at(node, key(path, "can_id"), "missing required key 'can_id'",
                    "the frame's identifier, e.g. can_id: 0x123 (11 bits) or 0x18FF0001 with extended: true");
    return false;
  }
  const auto id =
      reader.unsigned_int(node["can_id"], key(path, "can_id"), 0, frame.extended ? kExtendedIdMax : kStandardIdMax);
  if (!id) return false;
  frame.can_id = static_cast<std::uint32_t>(*id);
  return check_can_frame(reader, node, path, segment, frame, binding);
}

// What every native CAN frame must be: not an etag of the binding protocols, not declared background.
bool check_can_frame(YamlReader& reader, const YAML::Node& node, const std::string& path, const SegmentSpec& segment,
                     const NativeCanFrame& frame, NativeBinding& binding) {
  const YAML::Node& where = node["can_id"] ? node["can_id"] : node["message"] ? node["message"] : node;
  const std::string where_path = node["can_id"] ? key(path, "can_id") : node["message"] ? key(path, "message") : path;
  // COSMIC and FAMOUSO devices read an extended identifier's low 14 bits as an etag: one of the
  // binding protocols' etags would be taken for a protocol message by every such device.
  const auto etag = static_cast<std::uint16_t>(frame.can_id & kEtagMask);
  if (frame.extended && etag <= kHighestReservedEtag) {
    reader.error_at(where, where_path,
                    "extended identifier " + can_id_text(frame.can_id, true) + " has etag bits " +
                        std::to_string(etag) + ", which the binding protocols use (0.." +
                        std::to_string(kHighestReservedEtag) + ")",
                    "an extended identifier whose low 14 bits are above " + std::to_string(kHighestReservedEtag) +
                        ", or a standard identifier");
    return false;
  }
  const auto& background = segment.can.background;
  const auto declared = std::find_if(background.begin(), background.end(), [&](const CanBackgroundFrame& f) {
    return f.can_id == frame.can_id && f.extended == frame.extended;
  });
  if (declared != background.end()) {
    reader.error_at(where, where_path,
                    can_id_text(frame.can_id, frame.extended) + " is declared as background frame " + declared->name +
                        " (" + declared->origin + ") of segment " + segment.name,
                    "a frame is either background traffic or a channel: remove it from the background");
    return false;
  }
  binding.can = frame;
  return true;
}

bool parse_lcm(YamlReader& reader, const YAML::Node& node, const std::string& path, NativeBinding& binding) {
  if (!reader.check_map(node, path, {"channel", "representation"})) return false;
  if (!parse_form(reader, node, path, {"lcm", "compact", "json"}, binding)) return false;
  if (!node["channel"]) {
    reader.error_at(node, key(path, "channel"), "missing required key 'channel'",
                    "the LCM channel name, e.g. channel: POSE");
    return false;
  }
  const auto name = reader.string(node["channel"], key(path, "channel"));
  if (!name) return false;
  if (name->empty()) {
    reader.error_at(node["channel"], key(path, "channel"), "empty LCM channel name",
                    "the LCM channel name, e.g. channel: POSE");
    return false;
  }
  if (const Result<void> carried = check_transport_name(SegmentType::lcm, *name); !carried) {
    reader.error_at(node["channel"], key(path, "channel"), carried.error().text, "a shorter name");
    return false;
  }
  binding.lcm_channel = *name;
  return true;
}

std::optional<std::string> name_at(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                   const char* name, const char* hint) {
  if (!node[name]) {
    reader.error_at(node, key(path, name), std::string("missing required key '") + name + "'", hint);
    return std::nullopt;
  }
  return reader.string(node[name], key(path, name));
}

constexpr const char* kTopicHint = "a DDS topic name, e.g. topic: rt/cmd_vel (ROS 2 names its topics rt/<name>)";
constexpr const char* kTypeHint =
    "the DDS type name, e.g. type: geometry_msgs::msg::dds_::Twist_ (ROS 2: <pkg>::msg::dds_::<Name>_)";

bool parse_dds(YamlReader& reader, const YAML::Node& node, const std::string& path, NativeBinding& binding) {
  if (!reader.check_map(node, path, {"topic", "type", "representation", "keyed"})) return false;
  NativeDdsTopic topic;
  bool ok = true;
  if (const auto name = name_at(reader, node, path, "topic", kTopicHint)) {
    if (const Result<void> valid = check_dds_topic_name(*name); !valid) {
      reader.error_at(node["topic"], key(path, "topic"), valid.error().text, kTopicHint);
      ok = false;
    }
    topic.topic = *name;
  } else {
    ok = false;
  }
  if (const auto name = name_at(reader, node, path, "type", kTypeHint)) {
    if (const Result<void> valid = check_dds_type_name(*name); !valid) {
      reader.error_at(node["type"], key(path, "type"), valid.error().text, kTypeHint);
      ok = false;
    } else if (*name == kEnvelopeTypeName) {
      reader.error_at(node["type"], key(path, "type"),
                      std::string(kEnvelopeTypeName) + " is the gateway's own envelope type",
                      "leave out `native` on this segment to carry the channel as an envelope");
      ok = false;
    }
    topic.type = *name;
  } else {
    ok = false;
  }
  if (node["representation"]) {
    const auto text = reader.string(node["representation"], key(path, "representation"));
    if (text && (*text == "xcdr1" || *text == "xcdr2")) {
      topic.representation = *text == "xcdr2" ? DdsRepresentation::xcdr2 : DdsRepresentation::xcdr1;
    } else {
      if (text) {
        reader.error_at(node["representation"], key(path, "representation"), "unknown representation '" + *text + "'",
                        "xcdr1 (plain CDR, what ROS 2 and most types use) or xcdr2");
      }
      ok = false;
    }
  }
  if (node["keyed"]) {
    const auto keyed = reader.boolean(node["keyed"], key(path, "keyed"));
    if (keyed && *keyed) {
      reader.error_at(
          node["keyed"], key(path, "keyed"),
          "keyed types are not carried: an instance's key hash is computed from the type's key members, which "
          "the gateway does not know when it carries a sample as bytes",
          "a keyless type (ROS 2 messages are keyless), or carry the data as an envelope channel");
      ok = false;
    }
    if (!keyed) ok = false;
  }
  if (ok) binding.dds = std::move(topic);
  return ok;
}

}  // namespace

void parse_native(YamlReader& reader, const YAML::Node& node, const std::string& path, const Config& config,
                  ChannelSpec& channel, std::vector<std::string>& included) {
  if (!node.IsMap()) {
    reader.error_at(
        node, path, "expected a map of segment names to native identities",
        "native: {body: {can_id: 0x123}}, native: {viz: {channel: POSE}} or native: {lan: {topic: rt/cmd_vel, type: "
        "geometry_msgs::msg::dds_::Twist_}}");
    return;
  }
  for (const auto& entry : node) {
    const std::string name = entry.first.Scalar();
    const std::string entry_path = key(path, name);
    const SegmentSpec* segment = config.find_segment(name);
    if (!segment) {
      std::string known;
      for (const auto& s : config.segments) known += (known.empty() ? "" : ", ") + s.name;
      reader.error_at(entry.first, entry_path, "unknown segment '" + name + "'", "one of the segments: " + known);
      continue;
    }
    NativeBinding binding;
    binding.segment = name;
    bool ok = false;
    switch (segment->type) {
      case SegmentType::can:
        ok = parse_can(reader, entry.second, entry_path, *segment, included, binding);
        break;
      case SegmentType::lcm:
        ok = parse_lcm(reader, entry.second, entry_path, binding);
        break;
      case SegmentType::dds:
        ok = parse_dds(reader, entry.second, entry_path, binding);
        break;
      case SegmentType::replay:
        reader.error_at(entry.first, entry_path,
                        "segment '" + name + "' is a replay: its events are the recording's, with no native form",
                        "a CAN, DDS or LCM segment");
        break;
    }
    if (ok) channel.native.push_back(std::move(binding));
  }
}

void check_hop_segment(YamlReader& reader, const YAML::Node& node, const std::string& path, const ChannelSpec& channel,
                       const std::string& segment, const std::string& valid) {
  const bool used = std::count(channel.publishers.begin(), channel.publishers.end(), segment) +
                        std::count(channel.subscribers.begin(), channel.subscribers.end(), segment) >
                    0;
  if (used) return;
  YAML::Node where = node;
  for (const auto& entry : node) {
    if (entry.first.Scalar() == segment) where = entry.first;
  }
  reader.error_at(where, key(path, segment),
                  "segment '" + segment + "' is neither a publisher nor a subscriber of channel " + channel.name,
                  valid);
}

void check_native_segments(YamlReader& reader, const YAML::Node& node, const std::string& path,
                           const ChannelSpec& channel) {
  for (const NativeBinding& binding : channel.native)
    check_hop_segment(reader, node, path, channel, binding.segment,
                      "a native identity on one of the channel's segments");
}

void NativeDeclarations::add(YamlReader& reader, const YAML::Node& node, const std::string& path,
                             const ChannelSpec& channel, bool derived) {
  if (derived) deferred_.push_back(Deferred{channel.name, node, path});
  for (const NativeBinding& binding : channel.native) {
    const std::string identity = native_identity(binding);
    const int line = node[binding.segment].Mark().line + 1;
    const auto [it, fresh] = identities_.emplace(std::pair(binding.segment, identity), Owner{channel.name, line});
    if (fresh) continue;
    reader.error_at(node[binding.segment], key(path, binding.segment),
                    identity + " on segment " + binding.segment + " is already channel " + it->second.channel +
                        "'s (line " + std::to_string(it->second.line) + ")",
                    "one channel per native identity and segment");
  }
}

void NativeDeclarations::check_derived(YamlReader& reader, const Config& config) const {
  for (const Deferred& d : deferred_) {
    if (const ChannelSpec* channel = config.find_channel(d.channel))
      check_native_segments(reader, d.node, d.path, *channel);
  }
}

}  // namespace cosmic::config_detail
