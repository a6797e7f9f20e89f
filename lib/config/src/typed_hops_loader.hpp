// A typed channel's hops in the configuration (issue 35): the channel key `on_range`, and, once a
// document's channels and their publishers and subscribers are final, each hop's representation
// (cosmic/hop_representation.hpp) with the hop sizes and the channel's payload derived from them.
// Whether each hop can carry the type is admission's question (a bound, degraded or rejected
// verdict with the reason on that hop), not the configuration's. Internal to the config library.
#pragma once

#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// `on_range: drop|saturate` of the channel at `node` (absent: drop).
void parse_on_range(YamlReader& reader, const YAML::Node& node, const std::string& path, ChannelSpec& channel);

class TypedHopChecks {
 public:
  // Remembers where channel `channel` was declared (its map `node` at `path`).
  void add(const YAML::Node& node, const std::string& path, const ChannelSpec& channel);
  // For every channel added: a typed channel's hops (ChannelSpec::hop_payloads: each one's form
  // and size, or why it cannot carry the type) are set, and its payload becomes the largest of the
  // hops that fit unless `payload` was given (then it must hold each). An untyped channel may not
  // choose a representation (reported at the hop's `native` entry).
  void check(YamlReader& reader, std::vector<ChannelSpec>& channels, const std::vector<SegmentSpec>& segments) const;

 private:
  struct Declared {
    std::string channel;
    YAML::Node node;
    std::string path;
  };
  void check_one(YamlReader& reader, const Declared& declared, ChannelSpec& channel,
                 const std::vector<SegmentSpec>& segments) const;
  std::vector<Declared> declared_;
};

}  // namespace cosmic::config_detail
