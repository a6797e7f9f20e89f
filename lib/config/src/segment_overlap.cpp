#include "segment_overlap.hpp"

#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "cosmic/lcm_url.hpp"

namespace cosmic::config_detail {
namespace {

// UDP port of an LCM udpm URL, parsed canonically; nullopt for memq:// (private to each instance)
// and for URLs the loader refuses anyway.
std::optional<unsigned> lcm_port(const std::string& url) {
  const Result<LcmUrl> parsed = parse_lcm_url(url);
  if (!parsed || parsed.value().memq) return std::nullopt;
  return parsed.value().port;
}

struct Overlap {
  const char* key;      // the key that makes the two segments share a network
  std::string network;  // what they share, e.g. "UDP port 7667"
  const char* valid;
};

std::optional<Overlap> overlap(const SegmentSpec& a, const SegmentSpec& b) {
  if (a.type != b.type) return std::nullopt;
  if (!a.network.empty() && a.network == b.network) {
    return Overlap{"network", std::string(to_string(a.type)) + " network " + a.network,
                   "a different network name for each segment"};
  }
  switch (a.type) {
    case SegmentType::lcm: {
      const auto port = lcm_port(a.lcm.url);
      if (!port || port != lcm_port(b.lcm.url)) return std::nullopt;
      return Overlap{
          "url", "UDP port " + std::to_string(*port),
          "a different port for each LCM segment of one gateway (LCM receives every group sent to its port)"};
    }
    case SegmentType::dds: {
      const bool separate_servers = !a.dds.discovery_server.empty() && !b.dds.discovery_server.empty() &&
                                    a.dds.discovery_server != b.dds.discovery_server;
      if (a.dds.domain != b.dds.domain || separate_servers) return std::nullopt;
      return Overlap{"domain", "DDS domain " + std::to_string(a.dds.domain),
                     "a different domain, or a different discovery_server on each of the two"};
    }
    case SegmentType::can:
      if (a.can.interface != b.can.interface) return std::nullopt;
      return Overlap{"interface", "CAN interface " + a.can.interface, "one segment per CAN interface"};
    case SegmentType::replay:  // two replays of one file are two sources: nothing to share
      return std::nullopt;
  }
  return std::nullopt;
}

// Line (1-based) of the earlier segment named `name` among the first `count` list entries.
int line_of(const YAML::Node& segments, std::size_t count, const std::string& name) {
  for (std::size_t j = 0; j < count; ++j) {
    const YAML::Node entry = segments[j];
    if (entry.IsMap() && entry["name"] && entry["name"].IsScalar() && entry["name"].Scalar() == name) {
      return entry.Mark().line + 1;
    }
  }
  return 0;
}

}  // namespace

void check_segment_overlap(const YAML::Node& segments, std::size_t index, const SegmentSpec& segment,
                           const std::vector<SegmentSpec>& earlier, YamlReader& reader) {
  const YAML::Node node = segments[index];
  const std::string path = "segments[" + std::to_string(index) + "]";
  for (const SegmentSpec& other : earlier) {
    const auto shared = overlap(segment, other);
    if (!shared) continue;
    // Located at the key when written out; at the segment when the default is what collides.
    const bool written = node[shared->key] && !node[shared->key].IsNull();
    reader.error_at(written ? node[shared->key] : node, path + "." + shared->key,
                    "segment '" + segment.name + "' attaches the same network as segment '" + other.name + "' (line " +
                        std::to_string(line_of(segments, index, other.name)) + "): " + shared->network +
                        "; every message would come back in through the other one and loop",
                    shared->valid);
    return;  // one error per segment: the first segment it collides with
  }
}

}  // namespace cosmic::config_detail
