#include "federation_loader.hpp"

#include <algorithm>

namespace cosmic::config_detail {
namespace {

// A lease shorter than this would mark peers lost on ordinary scheduling delays; a longer one
// than an hour keeps a dead gateway's reservations far too long.
constexpr Nanos kMinLease{100'000'000};
constexpr Nanos kMaxLease{3'600'000'000'000};
// Two racing binds are decided when the window covers two control-loop ticks (100 ms each), the
// claim's delivery and the winner's committed announcement's (docs/federation.md): below 300 ms
// that cannot hold even on loopback. Longer than 10 s keeps binds waiting for nothing.
constexpr Nanos kMinClaimWindow{300'000'000};
constexpr Nanos kMaxClaimWindow{10'000'000'000};

}  // namespace

void parse_federation(YamlReader& reader, const YAML::Node& node, const std::string& path, FederationSpec& out) {
  if (!reader.check_map(node, path, {"segment", "lease", "claim_window"})) return;
  if (!has(node, "segment")) {
    reader.error_at(node, key(path, "segment"), "missing required key 'segment'",
                    "the name of a DDS segment to federate over");
    return;
  }
  if (auto v = reader.name(node["segment"], key(path, "segment"))) out.segment = *v;
  if (has(node, "lease")) {
    if (auto v = reader.duration(node["lease"], key(path, "lease"), false)) {
      if (*v < kMinLease || *v > kMaxLease) {
        reader.error_at(node["lease"], key(path, "lease"), "lease out of range", "from 100ms to 1h, e.g. 3s");
      } else {
        out.lease = *v;
      }
    }
  }
  if (has(node, "claim_window")) {
    if (auto v = reader.duration(node["claim_window"], key(path, "claim_window"), false)) {
      if (*v < kMinClaimWindow || *v > kMaxClaimWindow) {
        reader.error_at(node["claim_window"], key(path, "claim_window"), "claim_window out of range",
                        "from 300ms to 10s, e.g. 500ms");
      } else {
        out.claim_window = *v;
      }
    }
  }
}

void check_federation_segment(YamlReader& reader, const YAML::Node& node, const std::string& path,
                              const Config& config) {
  const FederationSpec& federation = config.gateway.federation;
  if (!federation.enabled() || !has(node, "segment")) return;
  const SegmentSpec* segment = config.find_segment(federation.segment);
  if (!segment) {
    std::string dds;
    for (const auto& s : config.segments) {
      if (s.type == SegmentType::dds) dds += (dds.empty() ? "" : ", ") + s.name;
    }
    reader.error_at(node["segment"], key(path, "segment"), "unknown segment '" + federation.segment + "'",
                    dds.empty() ? "a DDS segment (none is configured)" : "a DDS segment: " + dds);
  } else if (segment->type != SegmentType::dds) {
    reader.error_at(node["segment"], key(path, "segment"),
                    "segment '" + federation.segment + "' is " + to_string(segment->type),
                    "a DDS segment: gateways federate over DDS");
  }
}

}  // namespace cosmic::config_detail
