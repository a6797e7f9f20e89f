// A typed channel's type from an OMG IDL file (`type: {idl: FILE, name: pkg::msg::Name}`) or a ROS 2
// message (`type: {msg: FILE, name: pkg/msg/Name}`), with `max_length` bounding strings and
// sequences by member path and `type_path` the directories where #included IDL files and referenced
// messages are found (laid out as ROS 2 installs them: DIR/pkg/msg/Name.idl, DIR/pkg/msg/Name.msg).
// Besides type_path, the files are looked for next to FILE and, when FILE itself lies at
// ROOT/pkg/msg/Name.*, under ROOT. Every file read is added to `included`; every problem is reported
// located in the file it is in. Internal to the config library.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

std::optional<ChannelType> load_idl_type(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                         std::vector<std::string>& included);
std::optional<ChannelType> load_msg_type(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                         std::vector<std::string>& included);

// `max_length: {MEMBER: N}` of a type map (LCM, IDL, .msg): bounds 1..kMaxTypeBound by member path.
std::map<std::string, std::uint32_t> parse_max_length(YamlReader& reader, const YAML::Node& node,
                                                      const std::string& path);

}  // namespace cosmic::config_detail
