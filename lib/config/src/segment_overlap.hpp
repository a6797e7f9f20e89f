// Refuses segments that attach the same network twice: inside one gateway, two such segments
// receive each other's traffic and a single message circulates forever. Internal to the config
// library; called by the config parser for each segment, in document order.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reports, at the key that causes it, the first earlier segment (of `earlier`, the valid segments
// before it) that segment `index` of the `segments` list overlaps:
//   - LCM udpm: the same UDP port (LCM binds the port on every address, and Linux delivers a
//     group's datagrams to every socket bound to that port that joined any group);
//   - DDS: the same domain, unless both use a discovery server and the servers differ;
//   - CAN: the same interface.
void check_segment_overlap(const YAML::Node& segments, std::size_t index, const SegmentSpec& segment,
                           const std::vector<SegmentSpec>& earlier, YamlReader& reader);

}  // namespace cosmic::config_detail
