// The optional `fmus:` section (issue 38, docs/fmu.md): co-simulation FMUs run as components, their
// variables mapped to fields of typed channels. Internal to the config library; the config parser
// calls it once per document, after segments and channels and before the components, which then
// count each FMU as a component publishing its output channels and subscribing its input channels.
#pragma once

#include <yaml-cpp/yaml.h>

#include <span>
#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `root["fmus"]` into config.fmus: each FMU file read at load (its modelDescription.xml parsed
// and its binary for this platform found, nothing extracted; the file goes to `included`) and every
// mapping and parameter checked against it. Every problem goes to `reader` with its location.
void load_fmus(YamlReader& reader, const YAML::Node& root, Config& config, std::vector<std::string>& included);

// Names each FMU of `fmus` with its segment and step in ChannelSpec::fmu_publishers of the
// channels among `channels` it publishes (admission judges the step against them): at load, and
// for channels bound or replaced at run time from the running configuration's FMUs.
void add_fmu_publishers(std::span<const FmuSpec> fmus, std::vector<ChannelSpec>& channels);

}  // namespace cosmic::config_detail
