#include "federation_loader.hpp"

#include <algorithm>

#include "cosmic/certificate_subject.hpp"

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

// gateway.federation.peers: certificate subjects, each normalised (DER) for its participant keys.
void parse_peers(YamlReader& reader, const YAML::Node& node, const std::string& path,
                 std::vector<FederationPeerSpec>& out) {
  if (!reader.is_list(node, path)) return;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string at = indexed(path, i);
    const auto text = reader.string(node[i], at);
    if (!text) continue;
    auto subject = parse_certificate_subject(*text);
    if (!subject) {
      reader.error_at(node[i], at, "'" + *text + "' is not a certificate subject: " + subject.error().text,
                      "a subject as in the peer's certificate: CN=gateway-b,O=cosmic or /O=cosmic/CN=gateway-b");
      continue;
    }
    out.push_back(FederationPeerSpec{subject.value().text, subject.value().prefixes});
  }
}

}  // namespace

void parse_federation(YamlReader& reader, const YAML::Node& node, const std::string& path, FederationSpec& out) {
  if (!reader.check_map(node, path, {"segment", "lease", "claim_window", "peers"})) return;
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
  if (has(node, "peers")) parse_peers(reader, node["peers"], key(path, "peers"), out.peers);
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
  } else if (has(node, "peers") && !segment->dds.security) {
    // Without DDS Security a participant's subject is whatever it says: a list would only look safe.
    reader.error_at(node["peers"], key(path, "peers"),
                    "peers needs a secure federation segment: segment '" + federation.segment +
                        "' has no security, so no peer's subject can be authenticated",
                    "give segment " + federation.segment + " a security: section (docs/security.md), or remove peers");
  }
}

}  // namespace cosmic::config_detail
