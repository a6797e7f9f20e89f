// A CAN segment's `background`: the frames other devices send on the bus, declared in the YAML
// (`frames:`) and/or taken from a DBC file (`dbc:`, with `periods:` for event-driven messages and
// `ignore:`). Internal to the config library.
#pragma once

#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (the segment's `background` map) into `can.background` (YAML frames first, then the
// DBC's messages in file order). A DBC path is relative to the directory of the configuration file
// (reader.file()); every file read is appended to `included`. Every problem goes to `reader`: YAML
// ones at their YAML location, the DBC's at FILE:LINE:COL of the DBC.
void parse_background(YamlReader& reader, const YAML::Node& node, const std::string& path, CanSegmentProperties& can,
                      std::vector<std::string>& included);

}  // namespace cosmic::config_detail
