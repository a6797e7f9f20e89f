// A channel's `native` key (issue 19): per segment, the identity the devices already on that
// network use. CAN: `{can_id: 0x123, extended: false}` (the frame's data bytes are the contents);
// LCM: `{channel: NAME}` (raw contents on that LCM channel). Internal to the config library.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads `node` (the channel's `native` map) into `channel.native`, checking each entry against the
// segment's type and background declarations in `config`. Problems go to `reader` at their location.
// A native CAN frame given as a DBC message (the signal gateway) reads that file: its resolved path
// goes to `included`.
void parse_native(YamlReader& reader, const YAML::Node& node, const std::string& path, const Config& config,
                  ChannelSpec& channel, std::vector<std::string>& included);

// Reports `segment`, a key of the channel's map `node` (`native`, `secoc`), at that key when it is
// neither a publisher nor a subscriber of `channel`; `valid` says what belongs there.
void check_hop_segment(YamlReader& reader, const YAML::Node& node, const std::string& path, const ChannelSpec& channel,
                       const std::string& segment, const std::string& valid);

// Once the channel's publishers and subscribers are final (given or derived from components):
// every native entry names one of them. `node` is the channel's `native` map.
void check_native_segments(YamlReader& reader, const YAML::Node& node, const std::string& path,
                           const ChannelSpec& channel);

// The native identities of one document's channels: two channels with the same identity on a
// segment are an error (a CAN identifier has one sender; an LCM channel name carries one channel).
class NativeDeclarations {
 public:
  // `node` is the channel's `native` map. `derived`: the channel's publishers/subscribers come
  // from the components, so its entries are checked against them in check_derived().
  void add(YamlReader& reader, const YAML::Node& node, const std::string& path, const ChannelSpec& channel,
           bool derived);
  void check_derived(YamlReader& reader, const Config& config) const;

 private:
  struct Owner {
    std::string channel;
    int line = 0;
  };
  struct Deferred {
    std::string channel;
    YAML::Node node;
    std::string path;
  };
  std::map<std::pair<std::string, std::string>, Owner> identities_;  // (segment, identity text)
  std::vector<Deferred> deferred_;
};

}  // namespace cosmic::config_detail
