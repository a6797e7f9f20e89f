// A CAN segment's keys (can_segment_loader.hpp).
#include "can_segment_loader.hpp"

#include "background_loader.hpp"
#include "cosmic/transport_limits.hpp"

namespace cosmic::config_detail {
namespace {

constexpr std::uint64_t kClassicCanMaxBitrate = 1'000'000;
constexpr std::uint64_t kFdMaxDataBitrate = 8'000'000;

void parse_fault_hypothesis(YamlReader& reader, const YAML::Node& node, const std::string& path,
                            CanFaultHypothesis& errors) {
  if (!reader.check_map(node, path, {"max_per_window", "window"})) return;
  if (reader.require(node, path, "max_per_window", "a whole number of error frames, 0 for an error-free bus")) {
    if (auto v = reader.unsigned_int(node["max_per_window"], key(path, "max_per_window"), 0, 1000)) {
      errors.max_per_window = static_cast<std::uint32_t>(*v);
    }
  }
  if (errors.max_per_window > 0 && reader.require(node, path, "window", "the window length, e.g. 10ms")) {
    if (auto v = reader.duration(node["window"], key(path, "window"), false)) errors.window = *v;
  } else if (has(node, "window")) {
    reader.duration(node["window"], key(path, "window"), false);
  }
}

}  // namespace

void parse_can(YamlReader& reader, const YAML::Node& node, const std::string& path, SegmentSpec& s,
               std::vector<std::string>& included) {
  reader.check_map(node, path,
                   {"name", "type", "interface", "profile", "bitrate", "fd", "data_bitrate", "errors",
                    "max_utilization", "background", "network"});
  CanSegmentProperties& can = s.can;
  if (reader.require(node, path, "interface", "a network interface such as can0")) {
    if (auto v = reader.string(node["interface"], key(path, "interface"))) {
      if (const Result<void> valid = check_interface_name(*v); !valid) {
        reader.error_at(node["interface"], key(path, "interface"), valid.error().text,
                        "a network interface such as can0");
      }
      can.interface = *v;
    }
  }
  if (has(node, "fd")) can.fd = reader.boolean(node["fd"], key(path, "fd")).value_or(false);
  if (has(node, "profile")) {
    const std::string p = key(path, "profile");
    if (auto v = reader.choice(node["profile"], p, {"cosmic", "famouso"})) can.profile = static_cast<CanProfile>(*v);
    if (can.profile == CanProfile::famouso && can.fd) {
      reader.error_at(node["profile"], p, "profile famouso is classic CAN only", "fd: false, or profile: cosmic");
    }
  }
  if (reader.require(node, path, "bitrate", "the nominal bit rate, e.g. 500kbit/s")) {
    if (auto v = reader.bitrate(node["bitrate"], key(path, "bitrate"))) {
      if (v->bits_per_second > kClassicCanMaxBitrate) {
        reader.error_at(node["bitrate"], key(path, "bitrate"), "CAN nominal bit rate above 1Mbit/s",
                        "at most 1Mbit/s; use fd: true with data_bitrate for faster data phases");
      }
      can.bitrate = *v;
    }
  }
  can.data_bitrate = can.bitrate;
  if (has(node, "data_bitrate")) {
    const std::string p = key(path, "data_bitrate");
    if (!can.fd) {
      reader.error_at(node["data_bitrate"], p, "data_bitrate needs fd: true", "remove it, or set fd: true");
    } else if (auto v = reader.bitrate(node["data_bitrate"], p)) {
      if (*v < can.bitrate || v->bits_per_second > kFdMaxDataBitrate) {
        reader.error_at(node["data_bitrate"], p, "data bit rate out of range",
                        "from the nominal bitrate up to 8Mbit/s");
      }
      can.data_bitrate = *v;
    }
  }
  if (has(node, "errors")) parse_fault_hypothesis(reader, node["errors"], key(path, "errors"), can.errors);
  if (has(node, "background")) parse_background(reader, node["background"], key(path, "background"), can, included);
}

}  // namespace cosmic::config_detail
