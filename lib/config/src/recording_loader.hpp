// The `recording:` section (issue 37, docs/recording.md): where cosmicd writes MCAP files, which
// channels, compression, chunking, rotation, the writer's memory bound, and the CAN segments also
// logged as `candump -l`.
#pragma once

#include <string>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (a map) into `out`; every problem goes to `reader` with its location.
void parse_recording(YamlReader& reader, const YAML::Node& node, const std::string& path, RecordingSpec& out);

// What needs the whole configuration: each channel name without a glob character names a channel,
// each `candump` entry a CAN segment.
void check_recording(YamlReader& reader, const YAML::Node& node, const std::string& path, const Config& config);

}  // namespace cosmic::config_detail
