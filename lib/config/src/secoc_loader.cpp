// A channel's `secoc` key (secoc_loader.hpp).
#include "secoc_loader.hpp"

#include "key_file_loader.hpp"
#include "native_loader.hpp"

namespace cosmic::config_detail {
namespace {

constexpr std::size_t kSecocKeyBytes = 16;  // AES-128

// `bits` of a MAC or freshness value: whole bytes from `min` to `max` bits.
std::optional<std::uint32_t> byte_bits(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                       std::uint64_t min, std::uint64_t max, const std::string& why) {
  const auto bits = reader.unsigned_int(node, path, min, max);
  if (!bits) return std::nullopt;
  if (*bits % 8 != 0) {
    reader.error_at(node, path, std::to_string(*bits) + " bits is not a whole number of bytes",
                    "a multiple of 8 from " + std::to_string(min) + " to " + std::to_string(max) + why);
    return std::nullopt;
  }
  return static_cast<std::uint32_t>(*bits);
}

std::optional<SecocSpec> parse_entry(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                     std::vector<std::string>& included) {
  if (!reader.check_map(node, path, {"key_file", "mac_bits", "freshness_bits", "data_id", "cost"})) return std::nullopt;
  SecocSpec spec;
  bool ok = true;
  if (has(node, "key_file")) {
    auto loaded =
        load_key_file(reader, node["key_file"], key(path, "key_file"), included, kSecocKeyBytes, kSecocKeyBytes);
    ok = loaded.has_value();
    if (loaded) {
      spec.key_file = loaded->path;
      spec.key = std::move(loaded->key);
    }
  } else {
    if (!node["key_file"]) {  // present without a value: check_map reports it
      reader.error_at(node, key(path, "key_file"), "missing required key 'key_file'",
                      "an AES-128 key file: openssl rand -hex 16 > FILE; chmod 600 FILE");
    }
    ok = false;
  }
  if (has(node, "mac_bits")) {
    const auto bits = byte_bits(reader, node["mac_bits"], key(path, "mac_bits"), 8, 128, " (24: AUTOSAR's profile 1)");
    ok = ok && bits;
    spec.mac_bits = bits.value_or(spec.mac_bits);
  }
  if (has(node, "freshness_bits")) {
    // Without freshness bits in the frame a receiver could follow a restarted sender only by
    // trying every value it may have skipped; the counter is persisted in steps a receiver can follow.
    const auto bits = byte_bits(reader, node["freshness_bits"], key(path, "freshness_bits"), 8, 64,
                                " (the gateway persists its counter in steps a receiver must be able to follow)");
    ok = ok && bits;
    spec.freshness_bits = bits.value_or(spec.freshness_bits);
  }
  if (has(node, "data_id")) {
    const auto id = reader.unsigned_int(node["data_id"], key(path, "data_id"), 0, UINT32_MAX);
    ok = ok && id;
    if (id) spec.data_id = static_cast<std::uint32_t>(*id);
  }
  if (has(node, "cost")) {
    const auto cost = reader.duration(node["cost"], key(path, "cost"), true);
    ok = ok && cost;
    spec.cost = cost;
  }
  if (!ok) return std::nullopt;
  return spec;
}

void check_segments(YamlReader& reader, const YAML::Node& node, const std::string& path, const ChannelSpec& channel) {
  for (const SecocSpec& spec : channel.secoc)
    check_hop_segment(reader, node, path, channel, spec.segment, "SecOC on one of the channel's CAN segments");
}

}  // namespace

void parse_secoc(YamlReader& reader, const YAML::Node& node, const std::string& path, const Config& config,
                 ChannelSpec& channel, std::vector<std::string>& included) {
  if (!node.IsMap()) {
    reader.error_at(node, path, "expected a map of CAN segment names to SecOC settings",
                    "secoc: {body-can: {key_file: secoc.key}}");
    return;
  }
  for (const auto& entry : node) {
    const std::string segment = entry.first.Scalar();
    const std::string at = key(path, segment);
    const SegmentSpec* found = config.find_segment(segment);
    if (found == nullptr || found->type != SegmentType::can) {
      reader.error_at(entry.first, at,
                      found == nullptr ? "unknown segment '" + segment + "'"
                                       : "segment '" + segment + "' is not a CAN segment (SecOC protects CAN frames)",
                      "a CAN segment declared under segments");
      continue;
    }
    if (auto spec = parse_entry(reader, entry.second, at, included)) {
      spec->segment = segment;
      channel.secoc.push_back(std::move(*spec));
    }
  }
}

void SecocDeclarations::add(YamlReader& reader, const YAML::Node& node, const std::string& path,
                            const ChannelSpec& channel, bool derived) {
  if (derived) {
    deferred_.push_back(Deferred{channel.name, node, path});
  } else {
    check_segments(reader, node, path, channel);
  }
}

void SecocDeclarations::check_derived(YamlReader& reader, const Config& config) const {
  for (const Deferred& d : deferred_) {
    if (const ChannelSpec* channel = config.find_channel(d.channel)) check_segments(reader, d.node, d.path, *channel);
  }
}

}  // namespace cosmic::config_detail
