// A channel's `type` key (issue 35, docs/yaml-reference.md "type"): the contents as a record of
// named fields, written inline:
//   type:
//     fields:
//       - {name: distance, type: float32, unit: m, min: 0, max: 40}
//       - {name: state, type: enum, underlying: uint8, values: {OFF: 0, ON: 1}}
//       - {name: label, type: string, max_length: 32}
//       - {name: ranges, type: array, length: 16, element: float32, unit: m}
//       - {name: track, type: sequence, max_length: 100, element: {type: record, fields: [...]}}
//       - {name: pose, type: record, fields: [...]}
// Every problem is reported at its place in the file (cosmic::check_type()'s rules included).
// Internal to the config library.
#pragma once

#include <optional>
#include <string>

#include "cosmic/channel_type.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// The type `node` (the channel's `type` value) declares; nullopt after reporting why not.
std::optional<ChannelType> parse_channel_type(YamlReader& reader, const YAML::Node& node, const std::string& path);

// The YAML that parse_channel_type() reads back as `type` (the bind and state files write it).
YAML::Node channel_type_to_yaml(const ChannelType& type);

}  // namespace cosmic::config_detail
