// A CAN segment's keys (`type: can`): interface, profile, bit rates, the fault hypothesis and the
// background traffic of other ECUs (docs/yaml-reference.md#type-can).
#pragma once

#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (the segment's map) into `segment.can`; every problem goes to `reader` with its
// location; files read (DBC background) go to `included`.
void parse_can(YamlReader& reader, const YAML::Node& node, const std::string& path, SegmentSpec& segment,
               std::vector<std::string>& included);

}  // namespace cosmic::config_detail
