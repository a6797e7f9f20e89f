// A channel's `secoc` key (issue 36, item 4; docs/security.md): per CAN segment of the channel,
// `{key_file, mac_bits, freshness_bits, data_id, cost}`, the SecOC protection of its frames there
// (cosmic/model.hpp SecocSpec). Internal to the config library.
#pragma once

#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (the channel's `secoc` map) into `channel.secoc`: each key a CAN segment of
// `config`, the key file read (its resolved path to `included`), every problem at its key.
void parse_secoc(YamlReader& reader, const YAML::Node& node, const std::string& path, const Config& config,
                 ChannelSpec& channel, std::vector<std::string>& included);

// Every `secoc` entry names one of the channel's publishers or subscribers, once they are final
// (given, or derived from the components: check_derived()).
class SecocDeclarations {
 public:
  // `node` is the channel's `secoc` map; `derived`: the channel's lists come from the components.
  void add(YamlReader& reader, const YAML::Node& node, const std::string& path, const ChannelSpec& channel,
           bool derived);
  void check_derived(YamlReader& reader, const Config& config) const;

 private:
  struct Deferred {
    std::string channel;
    YAML::Node node;
    std::string path;
  };
  std::vector<Deferred> deferred_;
};

}  // namespace cosmic::config_detail
