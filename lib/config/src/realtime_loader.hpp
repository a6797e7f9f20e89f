// gateway.realtime: priorities, CPUs and memory locking of the forwarding threads.
#pragma once

#include <string>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (a map) into `out`; every problem goes to `reader` with its location.
void parse_realtime(YamlReader& reader, const YAML::Node& node, const std::string& path, RealtimeSpec& out);

}  // namespace cosmic::config_detail
