// The optional `components:` section (docs/components.md): the application's components, each on
// one segment, publishing and subscribing channels by name. Internal to the config library; the
// config parser calls it once per document, after segments and channels.
#pragma once

#include <yaml-cpp/yaml.h>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `root["components"]` into config.components and completes the channels from them:
// a channel whose `publishers` (`subscribers`) key was left out takes the segments of the
// components publishing (subscribing) it, in segment order; subscribers on a publisher segment
// receive there directly and add no S tag. Every problem goes to `reader` with its location.
// A channel given both lists keeps them and its components must agree with them.
void load_components(YamlReader& reader, const YAML::Node& root, Config& config);

// True when a channel map may omit publishers/subscribers: the document has components.
bool has_components(const YAML::Node& root);

}  // namespace cosmic::config_detail
