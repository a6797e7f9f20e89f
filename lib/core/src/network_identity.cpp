#include "cosmic/network_identity.hpp"

#include <variant>

#include "cosmic/lcm_url.hpp"

namespace cosmic {

std::string network_identity(const SegmentSpec& segment) {
  if (!segment.network.empty()) return std::string(to_string(segment.type)) + ":" + segment.network;
  switch (segment.type) {
    case SegmentType::can:
    case SegmentType::replay:  // a file in this process: no network shared with anyone
      return {};
    case SegmentType::dds:
      return "dds:domain=" + std::to_string(segment.dds.domain) +
             (segment.dds.discovery_server.empty() ? "" : ";server=" + segment.dds.discovery_server);
    case SegmentType::lcm: {
      const Result<LcmUrl> url = parse_lcm_url(segment.lcm.url);
      if (!url || url.value().memq) return {};
      return "lcm:" + url.value().group + ":" + std::to_string(url.value().port);
    }
  }
  return {};
}

}  // namespace cosmic
