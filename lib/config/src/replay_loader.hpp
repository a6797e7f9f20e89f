// A replay segment (issue 37, `type: replay`, docs/recording.md): the recording it publishes, which
// of its channels, at what speed, from where, looped or not; and, read from the file at load, what
// each selected channel holds (events, tightest spacing) for admission.
#pragma once

#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (the segment's map) into `segment.replay`; every problem goes to `reader` with its
// location; the recording read goes to `included`.
void parse_replay(YamlReader& reader, const YAML::Node& node, const std::string& path, SegmentSpec& segment,
                  std::vector<std::string>& included);

}  // namespace cosmic::config_detail
