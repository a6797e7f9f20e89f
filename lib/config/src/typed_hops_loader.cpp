#include "typed_hops_loader.hpp"

#include <algorithm>

#include "cosmic/hop_representation.hpp"

namespace cosmic::config_detail {

void parse_on_range(YamlReader& reader, const YAML::Node& node, const std::string& path, ChannelSpec& channel) {
  if (!has(node, "on_range")) return;
  const auto choice = reader.choice(node["on_range"], key(path, "on_range"), {"drop", "saturate"});
  if (choice) channel.on_range = *choice == 1 ? RangePolicy::saturate : RangePolicy::drop;
}

void TypedHopChecks::add(const YAML::Node& node, const std::string& path, const ChannelSpec& channel) {
  declared_.push_back(Declared{channel.name, node, path});
}

void TypedHopChecks::check(YamlReader& reader, std::vector<ChannelSpec>& channels,
                           const std::vector<SegmentSpec>& segments) const {
  for (const Declared& declared : declared_) {
    const auto channel = std::find_if(channels.begin(), channels.end(),
                                      [&](const ChannelSpec& c) { return c.name == declared.channel; });
    if (channel != channels.end()) check_one(reader, declared, *channel, segments);
  }
}

namespace {
// Where a problem of the hop on `segment` is reported: its `native` entry, else the channel's type.
std::pair<YAML::Node, std::string> hop_location(const YAML::Node& node, const std::string& path,
                                                const std::string& segment) {
  if (node["native"] && node["native"].IsMap() && node["native"][segment]) {
    return {node["native"][segment], key(key(path, "native"), segment)};
  }
  return {node["type"] ? node["type"] : node, key(path, "type")};
}
}  // namespace

void TypedHopChecks::check_one(YamlReader& reader, const Declared& declared, ChannelSpec& channel,
                               const std::vector<SegmentSpec>& segments) const {
  const YAML::Node& node = declared.node;
  if (!channel.type) {
    for (const NativeBinding& native : channel.native) {
      if (native.can && native.can->dbc_message) {
        const auto [where, at] = hop_location(node, declared.path, native.segment);
        reader.error_at(where["dbc"], key(at, "dbc"),
                        "a DBC message on a native hop carries a typed channel's fields, and this channel has no type",
                        "a type: for the channel (e.g. type: {dbc: FILE, message: NAME}), or can_id: alone");
        continue;
      }
      if (native.form == NativeForm::source) continue;
      const auto [where, at] = hop_location(node, declared.path, native.segment);
      reader.error_at(where["representation"], key(at, "representation"),
                      "representation chooses the form of a typed channel's events, and this channel has no type",
                      "a type: for the channel, or leave out representation (the contents cross as bytes)");
    }
    return;
  }
  // A hop that cannot carry the type is admission's to judge (check "representation"): the
  // configuration stays loadable and the other channels run.
  const TypedHops hops = typed_hops(channel, segments);
  const std::uint64_t largest = hops.largest();
  channel.hop_payloads = hops.payloads;
  if (!has(node, "payload")) {
    channel.payload = largest;
    return;
  }
  if (channel.payload >= largest) return;
  std::string needs = "the compact layout's " + std::to_string(hops.compact_size) + " B";
  for (const HopPayload& hop : hops.payloads) {
    if (hop.bytes == largest) needs = std::to_string(hop.bytes) + " B on segment " + hop.segment;
  }
  reader.error_at(
      node["payload"], key(declared.path, "payload"),
      "payload " + std::to_string(channel.payload) + " B is less than an event of the type takes: " + needs,
      "leave out payload on a typed channel (its hops' sizes give it), or at least " + std::to_string(largest) + "B");
}

}  // namespace cosmic::config_detail
