// gateway.metrics: where cosmicd serves /metrics (docs/metrics.md). A host outside loopback shows
// the gateway's channels and load to the network, so it needs an explicit allow_remote: true.
#pragma once

#include <optional>
#include <string>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// The endpoint `node` (a map) names, or nullopt after reporting every problem with its place.
std::optional<MetricsSpec> parse_metrics(YamlReader& reader, const YAML::Node& node, const std::string& path);

}  // namespace cosmic::config_detail
