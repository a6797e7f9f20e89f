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
// or from a DBC message (cosmic/dbc_type.hpp says how signals become fields):
//   type: {dbc: body.dbc, message: WheelSpeeds}
// Every problem is reported at its place in the file (cosmic::check_type()'s rules included).
// Internal to the config library.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// The type `node` (the channel's `type` value) declares; nullopt after reporting why not. A DBC
// file it names is added to `included` (ConfigResult::included_files).
std::optional<ChannelType> parse_channel_type(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                              std::vector<std::string>& included);

// The YAML that parse_channel_type() reads back as `type` (the bind and state files write it): the
// fields, or for a type from a DBC its source.
YAML::Node channel_type_to_yaml(const ChannelType& type);

}  // namespace cosmic::config_detail
