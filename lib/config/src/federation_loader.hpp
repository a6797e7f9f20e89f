// gateway.federation (docs/federation.md): the DDS segment the gateway federates over and the lease.
#pragma once

#include <optional>
#include <string>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (a map) into `out`; every problem goes to `reader` with its location. The segment
// is checked once the segments are known (check_federation_segment).
void parse_federation(YamlReader& reader, const YAML::Node& node, const std::string& path, FederationSpec& out);

// The named segment must exist and be a DDS segment; `node` is gateway.federation.
void check_federation_segment(YamlReader& reader, const YAML::Node& node, const std::string& path,
                              const Config& config);

}  // namespace cosmic::config_detail
